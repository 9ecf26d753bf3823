// TimeLimit: the episode-length wrapper that Gymnasium's make() applies to registered envs.
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "envs/env.h"

namespace rl::envs {

/// Wraps an Env and sets `truncated` on the step where the number of steps since the last Reset
/// reaches max_episode_steps (elapsed >= max, so with a limit of 500 the 500th step is truncated,
/// the 499th is not). `terminated` passes through unchanged, so both can be true on one step. The
/// Reset itself does not count as a step. Stepping on past the limit keeps counting and keeps
/// reporting truncated, as Gymnasium does. Not thread-safe.
class TimeLimit : public Env {
 public:
  /// Takes ownership of `env`. Throws std::invalid_argument if env is null or max_episode_steps is
  /// not positive.
  TimeLimit(std::unique_ptr<Env> env, int max_episode_steps);

  /// The wrapped env's spec with max_episode_steps replaced by this wrapper's limit.
  const EnvSpec& spec() const override { return spec_; }

  /// Resets the wrapped env and the step counter.
  void Reset(uint64_t seed) override;
  void Reset() override;
  /// Steps the wrapped env; if it throws, the step counter is unchanged.
  StepResult Step(int action) override;
  /// The same for continuous actions (forwarded to the wrapped env's StepContinuous).
  StepResult StepContinuous(std::span<const float> action) override;

  std::span<const float> observation() const override { return env_->observation(); }
  void Render(std::vector<uint8_t>* rgb, int* width, int* height) const override;
  void RenderSized(int width, int height, std::vector<uint8_t>* rgb) const override;

  /// Steps taken since the last Reset.
  int64_t elapsed_steps() const { return elapsed_steps_; }
  int max_episode_steps() const { return spec_.max_episode_steps; }

  /// The wrapped env (Gymnasium's `env.env`).
  Env& wrapped_env() { return *env_; }
  const Env& wrapped_env() const { return *env_; }

 private:
  // Counts a step the wrapped env completed and sets truncated at the limit.
  StepResult Count(StepResult result);

  std::unique_ptr<Env> env_;
  EnvSpec spec_;
  int64_t elapsed_steps_ = 0;
};

}  // namespace rl::envs
