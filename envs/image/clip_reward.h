// ClipReward: the last, optional stage of the pixel pipeline (pixel_env.h). Clamps every reward
// to [-1, 1], as DQN does (Mnih et al., 2015) and Gymnasium's ClipReward wrapper can.
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "envs/env.h"

namespace rl::envs {

/// Wraps any env and clamps the reward of each Step (or StepContinuous) to [-1, 1]; a NaN reward
/// passes through unchanged. Everything else, frame() included, is forwarded. Not thread-safe.
class ClipReward : public Env {
 public:
  /// Takes ownership of `env`. Throws std::invalid_argument if env is null.
  explicit ClipReward(std::unique_ptr<Env> env);

  const EnvSpec& spec() const override { return env_->spec(); }
  void Reset(uint64_t seed) override { env_->Reset(seed); }
  void Reset() override { env_->Reset(); }
  /// Steps the wrapped env and clamps the reward; flags pass through.
  StepResult Step(int action) override;
  StepResult StepContinuous(std::span<const float> action) override;

  std::span<const float> observation() const override { return env_->observation(); }
  std::span<const uint8_t> frame() const override { return env_->frame(); }
  void Render(std::vector<uint8_t>* rgb, int* width, int* height) const override;
  void RenderSized(int width, int height, std::vector<uint8_t>* rgb) const override;

 private:
  std::unique_ptr<Env> env_;
};

}  // namespace rl::envs
