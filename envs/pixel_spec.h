// Env ids with an image pipeline: "<id>+pixels(<key>=<value>,...)".
//
// A run names its env with one string that every process reads (the preset's `env` key), so the
// pixel pipeline is part of that string: "Catch-v0+pixels(width=5,height=10,stack=2)" is Catch
// rendered, reduced to 10 x 5 grayscale frames and stacked by two. Keys (defaults as in
// ImagePipelineConfig): width, height, stack, skip, max-pool, crop-top, crop-bottom, crop-left,
// crop-right, render-width, render-height, noop-start, time-limit; and rules of CarRacing's own
// (CarRacingConfig): off-track and lap-ends, which the TD3 CarRacing article's pipeline changes,
// off-track-grace, and pedals (gas and brake as one axis: an action form, not a rule). Reward
// clipping is not a key: it is a training choice (the actor's
// --clip-rewards), and evaluations score unclipped returns.
#pragma once

#include <string>

#include "envs/image/image_config.h"

namespace rl::envs {

struct EnvIdParts {
  std::string base;           // the registered id, e.g. "Catch-v0"
  bool pixels = false;        // "+pixels(...)" was given
  ImagePipelineConfig image;  // its settings (validated) when pixels is true
  // CarRacing's rules (CarRacingConfig::off_track and lap_ends); other envs refuse a change.
  bool off_track = false;
  int off_track_grace = 0;  // CarRacingConfig::off_track_grace, with off-track only
  bool lap_ends = true;
  bool pedals = false;  // CarRacingConfig::pedals, CarRacing-v3 only
};

/// Splits and parses an env id. Throws std::invalid_argument naming the problem: an unknown key,
/// a value that is not an integer (0/1 for max-pool, off-track, lap-ends and pedals), a missing
/// ")" or text after it, settings that ImagePipelineConfig::Validate() refuses, off-track or
/// lap-ends changed for an env other than CarRacing, pedals for one other than CarRacing-v3, or
/// an off-track-grace below 0 or without off-track.
EnvIdParts ParseEnvId(const std::string& id);

}  // namespace rl::envs
