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

namespace rl::envs {

/// Wraps an env (discrete or continuous); its image() is the RGB frame of the current state,
/// max-pooled over the last two inner steps. observation() is the wrapped env's, after its last
/// inner step. Not thread-safe.
class ActionRepeat : public ImageSource {
 public:
  /// Takes ownership of `env` and reads config's render_width, render_height, frame_skip,
  /// max_pool, noop_start and off_track. With render size 0,0 it resets `env` once with seed 0 and
  /// renders it, to learn the native size. Allocates all frame buffers. Throws
  /// std::invalid_argument if env is null or config.Validate() fails.
  ActionRepeat(std::unique_ptr<Env> env, const ImagePipelineConfig& config);

  /// The wrapped env's spec with max_episode_steps = ceil(wrapped / frame_skip).
  const EnvSpec& spec() const override { return spec_; }

  /// Reset the wrapped env and play noop_start zero actions (rewards discarded; reset again if
  /// the episode ends during them); the image is the frame rendered after that.
  void Reset(uint64_t seed) override;
  void Reset() override;

  /// Steps the wrapped env with `action` up to frame_skip times, stopping after the first inner
  /// step that reports terminated or truncated. Returns the sum of the inner rewards and the flags
  /// of the last inner step. With max_pool every inner step is rendered (which two frames are the
  /// last is known only when the loop stops); without, only the last. With off_track every inner
  /// step is rendered and tested: off the track, that inner step's reward becomes -10 and the
  /// Step ends terminated. Throws std::logic_error before the first Reset; exceptions of the
  /// wrapped env's Step (a bad action) pass through.
  StepResult Step(int action) override;
  /// The same for a continuous env.
  StepResult StepContinuous(std::span<const float> action) override;

  std::span<const float> observation() const override { return env_->observation(); }
  void Render(std::vector<uint8_t>* rgb, int* width, int* height) const override;
  void RenderSized(int width, int height, std::vector<uint8_t>* rgb) const override;

  /// RGB frames of the render size (or the wrapped env's native size).
  ImageShape image_shape() const override { return shape_; }
  /// The max-pooled frame of the current state (see Step).
  std::span<const uint8_t> image() const override;

 private:
  // Renders the wrapped env's current state into frames_[slot]. Throws std::logic_error if a
  // native-size Render changes size.
  void Capture(int slot);
  void Capture(std::vector<uint8_t>& frame);

  std::unique_ptr<Env> env_;
  // Repeats `inner_step` (one step of the wrapped env) as Step describes.
  template <class InnerStep>
  StepResult Repeat(const InnerStep& inner_step);

  EnvSpec spec_;
  int render_width_;
  int render_height_;
  int frame_skip_;
  bool max_pool_;
  int noop_start_;
  bool off_track_;
  ImageShape shape_;
  // Resets the wrapped env (`reset`), then plays noop_start zero actions, resetting again if the
  // episode ends during them (std::runtime_error after 10 such restarts).
  template <class InnerReset>
  void StartEpisode(const InnerReset& reset);
  // One inner step with the zero action (0, or each dimension's zero clipped into its bounds).
  StepResult NoOp();
  // Whether the raw frame in `frame` shows the car off the track (ImagePipelineConfig::off_track).
  bool OffTrack(const std::vector<uint8_t>& frame) const;
  std::vector<float> zero_action_;
  std::vector<uint8_t> probe_;  // the raw frame of an inner step, for the off-track test
  // frames_[0] and frames_[1]: the raw frames after the last two inner steps, alternating;
  // frames_[2]: their pixelwise max.
  std::array<std::vector<uint8_t>, 3> frames_;
  int current_ = -1;  // Index in frames_ of image(); -1 before the first Reset.
};

}  // namespace rl::envs
