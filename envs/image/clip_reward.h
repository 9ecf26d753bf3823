// ClipReward: the last, optional stage of the pixel pipeline (pixel_env.h). Clamps every reward
// to [-1, 1], as DQN does (Mnih et al., 2015) and Gymnasium's ClipReward wrapper can.
#pragma once

#include <memory>
#include <span>

#include "envs/env.h"
#include "envs/wrapper.h"

namespace rl::envs {

/// Wraps any env and clamps the reward of each Step to [-1, 1]; a NaN reward passes through
/// unchanged, and so do the flags. Everything else, frame() included, is forwarded. Not
/// thread-safe.
class ClipReward : public EnvWrapper<> {
 public:
  /// Takes ownership of `env`. Throws std::invalid_argument if env is null.
  explicit ClipReward(std::unique_ptr<Env> env);

 private:
  StepResult OnStep(std::span<const float> action) override;
};

}  // namespace rl::envs
