#include "envs/specs.h"

#include <algorithm>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "envs/image/image_config.h"
#include "envs/pixel_spec.h"

namespace rl::envs {

namespace {

EnvSpec WithId(const char* id, EnvSpec spec) {
  spec.id = id;
  return spec;
}

// Every registered id's spec, in the order of the list of envs (env_list.inc).
const std::vector<EnvSpec>& ListedSpecs() {
  static const std::vector<EnvSpec> specs = {
#define RL_ENV(env_id, factory, ...) WithId(env_id, EnvSpec __VA_ARGS__),
#include "envs/env_list.inc"
#undef RL_ENV
  };
  return specs;
}

}  // namespace

EnvSpec CartPoleSpec() { return LookupSpec("CartPole-v1"); }

EnvSpec CatchSpec() { return LookupSpec("Catch-v0"); }

EnvSpec PendulumSpec() { return LookupSpec("Pendulum-v1"); }

EnvSpec LunarLanderSpec(bool continuous) {
  return LookupSpec(continuous ? "LunarLanderContinuous-v3" : "LunarLander-v3");
}

EnvSpec CarRacingSpec(bool continuous, bool pedals) {
  EnvSpec spec = LookupSpec(continuous ? "CarRacing-v3" : "CarRacingDiscrete-v3");
  if (pedals) {
    spec.action_dim = 2;
    spec.action_low = {-1, -1};
    spec.action_high = {1, 1};
  }
  return spec;
}

EnvSpec KukaDiverseObjectSpec(bool is_test, int max_steps, int width, int height) {
  EnvSpec spec =
      LookupSpec(is_test ? "KukaDiverseObjectGraspingTest-v0" : "KukaDiverseObjectGrasping-v0");
  spec.max_episode_steps = max_steps;
  spec.render_width = width;
  spec.render_height = height;
  return spec;
}

EnvSpec PixelSpec(const EnvSpec& inner, const ImagePipelineConfig& config) {
  config.Validate();
  EnvSpec spec = inner;
  // ceil(inner limit / frame_skip): the outer step that contains the inner limit.
  const int inner_limit = config.time_limit > 0 ? config.time_limit : inner.max_episode_steps;
  spec.max_episode_steps =
      static_cast<int>((int64_t{inner_limit} + config.frame_skip - 1) / config.frame_skip);
  const int raw_width = config.render_width > 0 ? config.render_width : inner.render_width;
  const int raw_height = config.render_height > 0 ? config.render_height : inner.render_height;
  const int64_t cropped_width = int64_t{raw_width} - config.crop_left - config.crop_right;
  const int64_t cropped_height = int64_t{raw_height} - config.crop_top - config.crop_bottom;
  if (cropped_width <= 0 || cropped_height <= 0) {
    throw std::invalid_argument("pixels of " + inner.id + ": the crops leave no pixel of its " +
                                std::to_string(raw_width) + "x" + std::to_string(raw_height) +
                                " frames");
  }
  spec.frame_width = config.width > 0 ? config.width : static_cast<int>(cropped_width);
  spec.frame_height = config.height > 0 ? config.height : static_cast<int>(cropped_height);
  spec.frame_stack = config.stack;
  spec.observation_size = spec.frame_stack * spec.frame_height * spec.frame_width;
  return spec;
}

EnvSpec LookupSpec(const std::string& id) {
  const EnvIdParts parts = ParseEnvId(id);
  if (parts.pixels) {
    return PixelSpec(parts.pedals ? CarRacingSpec(true, true) : LookupSpec(parts.base),
                     parts.image);
  }
  for (const EnvSpec& spec : ListedSpecs()) {
    if (spec.id == id) return spec;
  }
  std::string known;
  for (const EnvSpec& spec : ListedSpecs()) known += (known.empty() ? "" : ", ") + spec.id;
  throw std::invalid_argument("unknown environment id \"" + id + "\"; known ids: " + known);
}

bool SameShape(const EnvSpec& a, const EnvSpec& b) {
  return a.observation_size == b.observation_size && a.frame_height == b.frame_height &&
         a.frame_width == b.frame_width && a.frame_stack == b.frame_stack &&
         a.num_actions == b.num_actions && a.action_dim == b.action_dim &&
         a.action_low == b.action_low && a.action_high == b.action_high;
}

std::vector<std::string> SpecIds() {
  std::vector<std::string> ids;
  for (const EnvSpec& spec : ListedSpecs()) ids.push_back(spec.id);
  std::sort(ids.begin(), ids.end());
  return ids;
}

}  // namespace rl::envs
