// Videos of the greedy policy for the report: one episode rendered frame by frame and encoded as
// WebM (VP8), which browsers play in a <video> element.
#pragma once

#include <cstdint>
#include <string>

#include "evaluator/progress.h"
#include "nn/sequential.h"

namespace rl::evaluator {

struct VideoResult {
  int frames = 0;  // frames written (the first observation and one per step)
  double episode_return = 0;
  int width = 0, height = 0;
};

/// The temporary file RecordGreedyVideo writes before it renames it to `path`: path + ".tmp.webm"
/// (the encoder takes the container from the extension). An evaluator killed while it encodes a
/// video leaves it behind.
std::string VideoTemporaryPath(const std::string& path);

/// Plays one episode of `env_id` reset with `seed`, acting greedily with `net` (epsilon 0),
/// renders every frame at width x height and writes it to `path` as WebM at `fps` frames per
/// second, atomically (a temporary file next to it, then rename). Throws std::runtime_error when
/// the encoder cannot be opened or the file cannot be written, std::invalid_argument when the
/// network does not fit the env. O(episode length x frame size).
/// `tick` (when set) is called after every step (progress.h).
VideoResult RecordGreedyVideo(nn::Sequential* net, const std::string& env_id, uint64_t seed,
                              int width, int height, double fps, const std::string& path,
                              const Tick& tick = {});

}  // namespace rl::evaluator
