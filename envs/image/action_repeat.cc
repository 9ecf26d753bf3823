#include "envs/image/action_repeat.h"

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <utility>

#include "common/check.h"

namespace rl::envs {

ActionRepeat::ActionRepeat(std::unique_ptr<Env> env, const ImagePipelineConfig& config)
    : EnvWrapper(std::move(env), "ActionRepeat"),
      render_width_(config.render_width),
      render_height_(config.render_height),
      frame_skip_(config.frame_skip),
      max_pool_(config.max_pool),
      noop_start_(config.noop_start) {
  config.Validate();
  EnvSpec& spec = mutable_spec();
  // ceil(max_episode_steps / frame_skip): the outer step that contains the inner limit.
  spec.max_episode_steps = static_cast<int>(
      (static_cast<int64_t>(spec.max_episode_steps) + frame_skip_ - 1) / frame_skip_);

  // The raw size: the requested one, or the native one, learnt from a throwaway episode.
  shape_ = ImageShape{.width = render_width_, .height = render_height_, .channels = 3};
  if (render_width_ == 0) {
    env_->Reset(0);
    env_->Render(&frames_[0], &shape_.width, &shape_.height);
  }
  for (std::vector<uint8_t>& frame : frames_) frame.resize(shape_.bytes());
  zero_action_.push_back(0.0f);  // The index 0 of a discrete env.
  if (spec.continuous()) {
    zero_action_.clear();
    for (int d = 0; d < spec.action_dim; ++d) {
      const auto i = static_cast<std::size_t>(d);
      zero_action_.push_back(std::clamp(0.0f, spec.action_low[i], spec.action_high[i]));
    }
  }
}

void ActionRepeat::OnReset(std::optional<uint64_t> seed) {
  current_ = -1;
  EnvWrapper::OnReset(seed);
  // An episode that ends during the no-ops starts again, a bounded number of times.
  constexpr int kMaxRestarts = 10;
  int restarts = 0;
  for (int i = 0; i < noop_start_; ++i) {
    const StepResult r = env_->Step(zero_action_);
    if (!r.terminated && !r.truncated) continue;
    if (++restarts > kMaxRestarts) {
      throw std::runtime_error("ActionRepeat: \"" + spec().id + "\" ended within " +
                               std::to_string(noop_start_) + " no-op steps " +
                               std::to_string(kMaxRestarts + 1) + " times; lower noop-start");
    }
    env_->Reset();
    i = -1;
  }
  Capture(0);
  current_ = 0;
}

StepResult ActionRepeat::OnStep(std::span<const float> action) {
  // Repeat the action, keeping the raw frames of the last two inner steps when max-pooling.
  StepResult total;
  int taken = 0;
  while (taken < frame_skip_) {
    const StepResult inner = env_->Step(action);
    ++taken;
    total.reward += inner.reward;
    total.terminated = inner.terminated;
    total.truncated = inner.truncated;
    if (max_pool_) Capture(taken % 2);
    if (inner.terminated || inner.truncated) break;
  }

  // The frame of this step: the last raw frame, or the max of the last two.
  if (!max_pool_) {
    Capture(0);
    current_ = 0;
  } else if (taken == 1) {
    current_ = 1;
  } else {
    std::transform(frames_[0].begin(), frames_[0].end(), frames_[1].begin(), frames_[2].begin(),
                   [](uint8_t a, uint8_t b) { return std::max(a, b); });
    current_ = 2;
  }
  return total;
}

void ActionRepeat::Capture(int slot) {
  std::vector<uint8_t>& frame = frames_[static_cast<std::size_t>(slot)];
  if (render_width_ > 0) {
    env_->RenderSized(render_width_, render_height_, &frame);
  } else {
    int width = 0;
    int height = 0;
    env_->Render(&frame, &width, &height);
    if (width != shape_.width || height != shape_.height) {
      throw std::logic_error("ActionRepeat: \"" + spec().id + "\" rendered " +
                             std::to_string(width) + "x" + std::to_string(height) +
                             " after rendering " + std::to_string(shape_.width) + "x" +
                             std::to_string(shape_.height) + "; the native size must not change");
    }
  }
  RL_CHECK(frame.size() == shape_.bytes())
      << "the wrapped env rendered " << frame.size() << " bytes, expected " << shape_.bytes();
}

std::span<const uint8_t> ActionRepeat::image() const {
  if (current_ < 0) throw std::logic_error("ActionRepeat: call Reset() before image()");
  return frames_[static_cast<std::size_t>(current_)];
}

}  // namespace rl::envs
