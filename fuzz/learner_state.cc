#include "fuzz/learner_state.h"

#include <stdexcept>

#include "envs/specs.h"
#include "learner/algorithm_state.h"
#include "learner/dqn.h"
#include "learner/td3.h"

namespace rl::fuzz {

std::vector<FuzzLearner>& FuzzLearners() {
  static std::vector<FuzzLearner>* learners = [] {
    auto* v = new std::vector<FuzzLearner>();
    learner::DqnConfig dqn;
    dqn.hidden = {8};
    const envs::EnvSpec cartpole = envs::CartPoleSpec();
    v->push_back(
        {"learner dqn", cartpole.id,
         std::make_unique<learner::Dqn>(cartpole.observation_size, cartpole.num_actions, dqn),
         std::mt19937_64(1)});
    learner::Td3Config td3;
    td3.hidden = {8, 8};
    const envs::EnvSpec pendulum = envs::PendulumSpec();
    v->push_back({"learner td3", pendulum.id, std::make_unique<learner::Td3>(pendulum, td3),
                  std::mt19937_64(2)});
    return v;
  }();
  return *learners;
}

StateFile SaveLearnerState(const FuzzLearner& l, int64_t env_steps) {
  StateFile state(l.kind);
  state.PutText("learner.env", l.env);
  state.PutInt("learner.env_steps", env_steps);
  state.PutText("learner.wall_seconds", "12.5");
  learner::PutRng(&state, "learner.shift_rng", l.shift_rng);
  l.algorithm->SaveState(&state);
  return state;
}

void LoadLearnerState(const StateFile& state, FuzzLearner* l) {
  if (state.Text("learner.env") != l->env) throw std::runtime_error("another env");
  l->algorithm->LoadState(state);
  (void)state.Int("learner.env_steps");
  (void)state.Text("learner.wall_seconds");
  learner::GetRng(state, "learner.shift_rng", &l->shift_rng);
}

}  // namespace rl::fuzz
