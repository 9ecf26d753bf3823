// The learners whose state files fuzz_state_file loads and fuzz_seeds writes: a DQN on CartPole-v1
// and a TD3 on Pendulum-v1, both with small MLPs so that a state file is a few kilobytes. Loading
// follows Learner::LoadState (learner/learner.cc) without the bus: the learner's own sections,
// then the algorithm's (learner/algorithm_state.h helpers).
#pragma once

#include <memory>
#include <random>
#include <string>
#include <vector>

#include "common/state_file.h"
#include "learner/algorithm.h"

namespace rl::fuzz {

struct FuzzLearner {
  std::string kind;  // the state file's kind, as Learner::StateKind()
  std::string env;
  std::unique_ptr<learner::Algorithm> algorithm;
  std::mt19937_64 shift_rng;
};

/// The DQN and the TD3 learner, built once (the same networks in every process).
std::vector<FuzzLearner>& FuzzLearners();

/// What Learner::SaveState writes for `l`, with `env_steps`.
StateFile SaveLearnerState(const FuzzLearner& l, int64_t env_steps);

/// Learner::LoadState's checks and restores for `l`. Throws std::runtime_error for a state that
/// does not fit, as the learner does.
void LoadLearnerState(const StateFile& state, FuzzLearner* l);

}  // namespace rl::fuzz
