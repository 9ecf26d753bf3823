// TimeLimit: the episode-length wrapper that Gymnasium's make() applies to registered envs.
#pragma once

#include <memory>
#include <span>

#include "envs/env.h"
#include "envs/wrapper.h"

namespace rl::envs {

/// Wraps an Env and sets `truncated` on the step where the number of steps since the last Reset
/// (elapsed_steps()) reaches max_episode_steps (elapsed >= max, so with a limit of 500 the 500th
/// step is truncated, the 499th is not). `terminated` passes through unchanged, so both can be
/// true on one step. The Reset itself does not count as a step, nor does a step that throws.
/// Stepping on past the limit keeps counting and keeps reporting truncated, as Gymnasium does.
/// Not thread-safe.
class TimeLimit : public EnvWrapper<> {
 public:
  /// Takes ownership of `env`; its spec is the wrapped env's with max_episode_steps replaced by
  /// this limit. Throws std::invalid_argument if env is null or max_episode_steps is not positive.
  TimeLimit(std::unique_ptr<Env> env, int max_episode_steps);

  int max_episode_steps() const { return spec().max_episode_steps; }

 private:
  StepResult OnStep(std::span<const float> action) override;
};

}  // namespace rl::envs
