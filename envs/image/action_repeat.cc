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
    : env_(std::move(env)),
      render_width_(config.render_width),
      render_height_(config.render_height),
      frame_skip_(config.frame_skip),
      max_pool_(config.max_pool),
      noop_start_(config.noop_start),
      off_track_(config.off_track) {
  if (env_ == nullptr) {
    throw std::invalid_argument("ActionRepeat: the wrapped env must not be null");
  }
  config.Validate();
  spec_ = env_->spec();
  // ceil(max_episode_steps / frame_skip): the outer step that contains the inner limit.
  spec_.max_episode_steps = static_cast<int>(
      (static_cast<int64_t>(spec_.max_episode_steps) + frame_skip_ - 1) / frame_skip_);

  // The raw size: the requested one, or the native one, learnt from a throwaway episode.
  shape_ = ImageShape{.width = render_width_, .height = render_height_, .channels = 3};
  if (render_width_ == 0) {
    env_->Reset(0);
    env_->Render(&frames_[0], &shape_.width, &shape_.height);
  }
  for (std::vector<uint8_t>& frame : frames_) frame.resize(shape_.bytes());
  probe_.resize(shape_.bytes());
  for (int d = 0; d < spec_.action_dim; ++d) {
    const auto i = static_cast<std::size_t>(d);
    zero_action_.push_back(std::clamp(0.0f, spec_.action_low[i], spec_.action_high[i]));
  }
}

template <class InnerReset>
void ActionRepeat::StartEpisode(const InnerReset& reset) {
  reset();
  // An episode that ends during the no-ops starts again, a bounded number of times.
  constexpr int kMaxRestarts = 10;
  int restarts = 0;
  for (int i = 0; i < noop_start_; ++i) {
    const StepResult r = NoOp();
    if (!r.terminated && !r.truncated) continue;
    if (++restarts > kMaxRestarts) {
      throw std::runtime_error("ActionRepeat: \"" + spec_.id + "\" ended within " +
                               std::to_string(noop_start_) + " no-op steps " +
                               std::to_string(kMaxRestarts + 1) + " times; lower noop-start");
    }
    env_->Reset();
    i = -1;
  }
  Capture(0);
  current_ = 0;
}

StepResult ActionRepeat::NoOp() {
  return spec_.continuous() ? env_->StepContinuous(zero_action_) : env_->Step(0);
}

void ActionRepeat::Reset(uint64_t seed) {
  StartEpisode([&] { env_->Reset(seed); });
}

void ActionRepeat::Reset() {
  StartEpisode([&] { env_->Reset(); });
}

bool ActionRepeat::OffTrack(const std::vector<uint8_t>& frame) const {
  // Row 75 and columns 41, 42, 52, 53 of the article's 96 x 96 frame, scaled to this one.
  const int row = 75 * shape_.height / 96;
  for (int column : {41, 42, 52, 53}) {
    const int x = column * shape_.width / 96;
    const std::size_t green = (static_cast<std::size_t>(row) * shape_.width + x) * 3 + 1;
    if (frame[green] <= 200) return false;
  }
  return true;
}

StepResult ActionRepeat::Step(int action) {
  return Repeat([&] { return env_->Step(action); });
}

StepResult ActionRepeat::StepContinuous(std::span<const float> action) {
  return Repeat([&] { return env_->StepContinuous(action); });
}

template <class InnerStep>
StepResult ActionRepeat::Repeat(const InnerStep& inner_step) {
  if (current_ < 0) throw std::logic_error("ActionRepeat: call Reset() before Step()");

  // Repeat the action, keeping the raw frames of the last two inner steps when max-pooling.
  StepResult total;
  int taken = 0;
  while (taken < frame_skip_) {
    StepResult inner = inner_step();
    ++taken;
    if (off_track_) {
      Capture(probe_);
      if (OffTrack(probe_)) {
        inner.reward = -10.0;
        inner.terminated = true;
      }
    }
    total.reward += inner.reward;
    total.terminated = inner.terminated;
    total.truncated = inner.truncated;
    if (max_pool_) {
      // With the off-track test the frame was rendered already.
      if (off_track_) {
        frames_[static_cast<std::size_t>(taken % 2)] = probe_;
      } else {
        Capture(taken % 2);
      }
    }
    if (inner.terminated || inner.truncated) break;
  }

  // The frame of this step: the last raw frame, or the max of the last two.
  if (!max_pool_) {
    if (off_track_) {
      std::swap(frames_[0], probe_);
    } else {
      Capture(0);
    }
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

void ActionRepeat::Capture(int slot) { Capture(frames_[static_cast<std::size_t>(slot)]); }

void ActionRepeat::Capture(std::vector<uint8_t>& frame) {
  if (render_width_ > 0) {
    env_->RenderSized(render_width_, render_height_, &frame);
  } else {
    int width = 0;
    int height = 0;
    env_->Render(&frame, &width, &height);
    if (width != shape_.width || height != shape_.height) {
      throw std::logic_error("ActionRepeat: \"" + spec_.id + "\" rendered " +
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

void ActionRepeat::Render(std::vector<uint8_t>* rgb, int* width, int* height) const {
  env_->Render(rgb, width, height);
}

void ActionRepeat::RenderSized(int width, int height, std::vector<uint8_t>* rgb) const {
  env_->RenderSized(width, height, rgb);
}

}  // namespace rl::envs
