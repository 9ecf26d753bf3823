#include "envs/time_limit.h"

#include <stdexcept>
#include <string>
#include <utility>

namespace rl::envs {

TimeLimit::TimeLimit(std::unique_ptr<Env> env, int max_episode_steps) : env_(std::move(env)) {
  if (env_ == nullptr) throw std::invalid_argument("TimeLimit: the wrapped env must not be null");
  if (max_episode_steps <= 0) {
    throw std::invalid_argument("TimeLimit: max_episode_steps must be positive, got " +
                                std::to_string(max_episode_steps));
  }
  spec_ = env_->spec();
  spec_.max_episode_steps = max_episode_steps;
}

void TimeLimit::Reset(uint64_t seed) {
  env_->Reset(seed);
  elapsed_steps_ = 0;
}

void TimeLimit::Reset() {
  env_->Reset();
  elapsed_steps_ = 0;
}

StepResult TimeLimit::Step(int action) { return Count(env_->Step(action)); }

StepResult TimeLimit::StepContinuous(std::span<const float> action) {
  return Count(env_->StepContinuous(action));
}

StepResult TimeLimit::Count(StepResult result) {
  ++elapsed_steps_;
  if (elapsed_steps_ >= spec_.max_episode_steps) result.truncated = true;
  return result;
}

void TimeLimit::Render(std::vector<uint8_t>* rgb, int* width, int* height) const {
  env_->Render(rgb, width, height);
}

void TimeLimit::RenderSized(int width, int height, std::vector<uint8_t>* rgb) const {
  env_->RenderSized(width, height, rgb);
}

}  // namespace rl::envs
