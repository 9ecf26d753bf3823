#include "envs/image/clip_reward.h"

#include <algorithm>
#include <utility>

namespace rl::envs {

ClipReward::ClipReward(std::unique_ptr<Env> env) : EnvWrapper(std::move(env), "ClipReward") {}

StepResult ClipReward::OnStep(std::span<const float> action) {
  StepResult result = env_->Step(action);
  // std::clamp returns a NaN unchanged.
  result.reward = std::clamp(result.reward, -1.0, 1.0);
  return result;
}

}  // namespace rl::envs
