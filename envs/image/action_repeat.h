// ActionRepeat: the first stage of the pixel pipeline (pixel_env.h). Repeats each action
// frame_skip times on the wrapped env, sums the rewards, renders the raw RGB frames and max-pools
// the last two, as in Mnih et al. (2015) and Gymnasium's AtariPreprocessing (frame_skip, with the
// max over the last two frames that removes Atari's flicker).
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "envs/env.h"
#include "envs/image/image_source.h"
#include "envs/image/pixel_env.h"
#include "envs/wrapper.h"

namespace rl::envs {

/// Wraps an env (discrete or continuous); its image() is the RGB frame of the current state,
/// max-pooled over the last two inner steps. observation() is the wrapped env's, after its last
/// inner step. Not thread-safe.
class ActionRepeat : public EnvWrapper<ImageSource> {
 public:
  /// Takes ownership of `env` and reads config's render_width, render_height, frame_skip,
  /// max_pool and noop_start. With render size 0,0 it resets `env` once with seed 0 and
  /// renders it, to learn the native size. Allocates all frame buffers. Throws
  /// std::invalid_argument if env is null or config.Validate() fails.
  ActionRepeat(std::unique_ptr<Env> env, const ImagePipelineConfig& config);

  // Its spec is the wrapped env's with max_episode_steps = ceil(wrapped / frame_skip).
  //
  // Reset resets the wrapped env and plays noop_start zero actions (rewards discarded; reset
  // again if the episode ends during them); the image is the frame rendered after that.
  //
  // Step steps the wrapped env with the action up to frame_skip times, stopping after the first
  // inner step that reports terminated or truncated, and returns the sum of the inner rewards
  // and the flags of the last inner step. With max_pool every inner step is rendered (which two
  // frames are the last is known only when the loop stops); without, only the last. Exceptions
  // of the wrapped env's Step pass through.

  /// RGB frames of the render size (or the wrapped env's native size).
  ImageShape image_shape() const override { return shape_; }
  /// The max-pooled frame of the current state (see Step).
  std::span<const uint8_t> image() const override;

 private:
  // Renders the wrapped env's current state into frames_[slot]. Throws std::logic_error if a
  // native-size Render changes size.
  void Capture(int slot);

  // Resets the wrapped env, then plays noop_start zero actions, resetting again if the episode
  // ends during them (std::runtime_error after 10 such restarts).
  void OnReset(std::optional<uint64_t> seed) override;
  StepResult OnStep(std::span<const float> action) override;

  int render_width_;
  int render_height_;
  int frame_skip_;
  bool max_pool_;
  int noop_start_;
  ImageShape shape_;
  // The zero action: 0 (the index), or each dimension's zero clipped into its bounds.
  std::vector<float> zero_action_;
  // frames_[0] and frames_[1]: the raw frames after the last two inner steps, alternating;
  // frames_[2]: their pixelwise max.
  std::array<std::vector<uint8_t>, 3> frames_;
  int current_ = -1;  // Index in frames_ of image(); -1 before the first Reset.
};

}  // namespace rl::envs
