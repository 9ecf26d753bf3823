// A scripted env for the image pipeline tests: hand-made frames, and scripted rewards and episode
// ends, so that every expected value can be worked out by hand.
#pragma once

#include <cstddef>
#include <cstdint>
#include <initializer_list>
#include <optional>
#include <span>
#include <stdexcept>
#include <utility>
#include <vector>

#include "envs/env.h"
#include "envs/image/image_source.h"

namespace rl::envs::testing {

// What one scripted inner step returns.
using ScriptedStep = StepResult;

// An ImageSource whose image after Reset is frames[0] and after the t-th Step of an episode is
// frames[t]; the t-th Step returns steps[t - 1] and throws std::logic_error past the script.
// Render() returns the current frame (so for ActionRepeat it is an ordinary rendered env), image()
// exposes it directly (so it also feeds FrameProcessor and FrameStack). observation() is the
// number of steps taken in the episode. Counts its calls.
class ScriptedImageEnv : public ImageSource {
 public:
  ScriptedImageEnv(ImageShape shape, std::vector<std::vector<uint8_t>> frames,
                   std::vector<ScriptedStep> steps = {})
      : ImageSource(EnvSpec{.id = "Scripted-v0",
                            .observation_size = 1,
                            .num_actions = 3,
                            .max_episode_steps = 10,
                            .reward_threshold = 2.5}),
        shape_(shape),
        frames_(std::move(frames)),
        steps_(std::move(steps)) {
    for (const auto& frame : frames_) {
      if (frame.size() != shape_.bytes()) throw std::invalid_argument("frame of the wrong size");
    }
  }

  // The spec to adjust before wrapping (e.g. max_episode_steps, or a continuous action space).
  using ImageSource::mutable_spec;

  std::span<const float> observation() const override { return observation_; }

  void Render(std::vector<uint8_t>* rgb, int* width, int* height) const override {
    ++renders;
    rgb->assign(current().begin(), current().end());
    *width = shape_.width;
    *height = shape_.height;
  }
  void RenderSized(int width, int height, std::vector<uint8_t>* rgb) const override {
    last_sized_width = width;
    last_sized_height = height;
    Env::RenderSized(width, height, rgb);
  }

  ImageShape image_shape() const override { return shape_; }
  std::span<const uint8_t> image() const override { return current(); }

  // Call counts and the last seed, for the tests.
  int resets = 0;
  int steps_taken = 0;
  mutable int renders = 0;
  uint64_t last_seed = ~uint64_t{0};
  mutable int last_sized_width = 0;
  mutable int last_sized_height = 0;
  std::vector<float> last_action;  // The action of the last Step.

 private:
  const std::vector<uint8_t>& current() const { return frames_.at(step_); }

  void OnReset(std::optional<uint64_t> seed) override {
    if (seed.has_value()) last_seed = *seed;
    ++resets;
    step_ = 0;
    observation_[0] = 0;
  }
  StepResult OnStep(std::span<const float> action) override {
    last_action.assign(action.begin(), action.end());
    if (step_ >= steps_.size()) throw std::logic_error("past the end of the script");
    ++step_;
    ++steps_taken;
    observation_[0] = static_cast<float>(step_);
    return steps_[step_ - 1];
  }

  ImageShape shape_;
  std::vector<std::vector<uint8_t>> frames_;
  std::vector<ScriptedStep> steps_;
  std::size_t step_ = 0;
  std::vector<float> observation_ = {0};
};

// An RGB frame whose pixels are gray (R = G = B = value), given row by row. OpenCV's RGB2GRAY
// maps such a pixel to its value exactly (the weights sum to 1).
inline std::vector<uint8_t> GrayRgb(std::initializer_list<uint8_t> values) {
  std::vector<uint8_t> rgb(values.size() * 3);
  std::size_t i = 0;
  for (uint8_t v : values) {
    for (int c = 0; c < 3; ++c) rgb[i++] = v;
  }
  return rgb;
}

// Shapes of the test frames.
inline ImageShape RgbShape(int width, int height) { return {width, height, 3}; }
inline ImageShape GrayShape(int width, int height) { return {width, height, 1}; }

}  // namespace rl::envs::testing
