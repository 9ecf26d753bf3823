#include "envs/image/clip_reward.h"

#include <algorithm>
#include <stdexcept>
#include <utility>

namespace rl::envs {
namespace {

// Clamps the reward to [-1, 1] (std::clamp returns a NaN unchanged).
StepResult Clip(StepResult result) {
  result.reward = std::clamp(result.reward, -1.0, 1.0);
  return result;
}

}  // namespace

ClipReward::ClipReward(std::unique_ptr<Env> env) : env_(std::move(env)) {
  if (env_ == nullptr) throw std::invalid_argument("ClipReward: the wrapped env must not be null");
}

StepResult ClipReward::Step(int action) { return Clip(env_->Step(action)); }

StepResult ClipReward::StepContinuous(std::span<const float> action) {
  return Clip(env_->StepContinuous(action));
}

void ClipReward::Render(std::vector<uint8_t>* rgb, int* width, int* height) const {
  env_->Render(rgb, width, height);
}

void ClipReward::RenderSized(int width, int height, std::vector<uint8_t>* rgb) const {
  env_->RenderSized(width, height, rgb);
}

}  // namespace rl::envs
