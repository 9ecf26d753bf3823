// FrameStack: the third stage of the pixel pipeline (pixel_env.h). Stacks the last `stack`
// grayscale frames of the wrapped ImageSource into a float observation in [0, 1], as in Mnih et
// al. (2015) and Gymnasium's FrameStackObservation (with padding_type "reset": after a reset the
// stack is the first frame repeated).
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "envs/env.h"
#include "envs/image/image_source.h"
#include "envs/image/pixel_env.h"
#include "envs/wrapper.h"

namespace rl::envs {

/// Wraps a grayscale ImageSource and makes it a pixel env (see EnvSpec): observation() is the
/// last `stack` frames, oldest first, each byte / 255.0f; frame() is the newest frame. After any
/// Reset every slot holds the first frame, so no frame of an earlier episode is ever visible.
/// Not thread-safe.
class FrameStack : public EnvWrapper<Env, ImageSource> {
 public:
  /// Takes ownership of `env` and reads config's stack. Allocates the observation. Throws
  /// std::invalid_argument if env is null, its images are not grayscale, config.Validate() fails,
  /// or the observation would exceed INT_MAX floats.
  FrameStack(std::unique_ptr<ImageSource> env, const ImagePipelineConfig& config);

  // Its spec is the wrapped env's with frame_height, frame_width and frame_stack set and
  // observation_size = frame_stack * frame_height * frame_width. Reset resets the wrapped env and
  // fills every slot of the stack with its first frame; Step steps it, drops the oldest frame and
  // appends the new one, O(observation_size).

  /// The stacked frames (all 0 before the first Reset).
  std::span<const float> observation() const override { return stacked_; }
  /// The newest frame, the wrapped env's image(). Throws std::logic_error before the first Reset.
  std::span<const uint8_t> frame() const override;

 private:
  void OnReset(std::optional<uint64_t> seed) override;
  StepResult OnStep(std::span<const float> action) override;
  // Writes the wrapped env's current image, divided by 255, into slot `slot` of the stack.
  void Store(int slot);

  std::size_t frame_size_;      // Pixels in one frame.
  std::vector<float> stacked_;  // frame_stack frames of frame_size_ floats, oldest first.
};

}  // namespace rl::envs
