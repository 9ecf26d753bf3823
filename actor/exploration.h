// Exploration schedules of the actors.
#pragma once

#include <cstdint>
#include <string>

namespace rl::actor {

// Ape-X (Horgan et al. 2018): actor i of n explores with the constant
// epsilon_i = base^(1 + alpha * i / (n - 1)); with one actor, epsilon = base.
double ApexEpsilon(int actor_index, int num_actors, double base = 0.4, double alpha = 7.0);

// Mnih et al. 2015: epsilon falls linearly from `start` to `end` over `anneal_steps` steps of
// this actor, then stays at `end`.
double LinearEpsilon(int64_t step, double start, double end, int64_t anneal_steps);

// How an actor picks its epsilon.
struct ExplorationConfig {
  std::string mode = "apex";      // "apex", "linear" or "constant"
  double apex_base = 0.4;         // Ape-X base epsilon
  double apex_alpha = 7.0;        // Ape-X exponent spread
  double start = 1.0;             // linear: first epsilon
  double end = 0.05;              // linear: final epsilon; constant: the epsilon
  int64_t anneal_steps = 100000;  // linear: steps from start to end

  // Throws std::invalid_argument on an unknown mode or an epsilon outside [0, 1].
  void Validate() const;
  // Epsilon of actor actor_index of num_actors after `step` steps.
  double Epsilon(int actor_index, int num_actors, int64_t step) const;
};

}  // namespace rl::actor
