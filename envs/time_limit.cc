#include "envs/time_limit.h"

#include <stdexcept>
#include <string>
#include <utility>

namespace rl::envs {

TimeLimit::TimeLimit(std::unique_ptr<Env> env, int max_episode_steps)
    : EnvWrapper(std::move(env), "TimeLimit") {
  if (max_episode_steps <= 0) {
    throw std::invalid_argument("TimeLimit: max_episode_steps must be positive, got " +
                                std::to_string(max_episode_steps));
  }
  mutable_spec().max_episode_steps = max_episode_steps;
}

StepResult TimeLimit::OnStep(std::span<const float> action) {
  StepResult result = env_->Step(action);
  if (elapsed_steps() >= max_episode_steps()) result.truncated = true;
  return result;
}

}  // namespace rl::envs
