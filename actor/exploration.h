// Exploration schedules of the actors: epsilon-greedy for discrete actions, Gaussian noise for
// continuous ones (see policy.h).
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

// How an actor explores.
//
// Discrete actions, epsilon-greedy: mode "apex", "linear" or "constant" (the epsilon fields).
// Continuous actions, mode "gaussian": the deterministic action plus Gaussian noise of standard
// deviation sigma * (high - low) / 2 in each dimension (sigma relative to the half-range, as
// TD3's 0.1 x max action), clipped to the bounds; sigma falls linearly from `sigma` to
// `sigma_end` over `sigma_anneal_steps` steps of the actor (0: constant), and actor i of n
// scales it by noise_spread^(i / (n - 1)) (Ape-X spirit: actors explore at different scales;
// 1: all alike). The first `start_steps` steps of each actor take uniform random actions.
struct ExplorationConfig {
  std::string mode = "apex";       // "apex", "linear", "constant" or "gaussian"
  double apex_base = 0.4;          // Ape-X base epsilon
  double apex_alpha = 7.0;         // Ape-X exponent spread
  double start = 1.0;              // linear: first epsilon
  double end = 0.05;               // linear: final epsilon; constant: the epsilon
  int64_t anneal_steps = 100000;   // linear: steps from start to end
  double sigma = 0.1;              // gaussian: first noise scale
  double sigma_end = 0.1;          // gaussian: final noise scale
  int64_t sigma_anneal_steps = 0;  // gaussian: steps from sigma to sigma_end (0: constant sigma)
  double noise_spread = 1.0;       // gaussian: last actor's sigma over the first's, in (0, 1]
  int64_t start_steps = 0;         // gaussian: uniform random actions first

  bool gaussian() const { return mode == "gaussian"; }
  // Throws std::invalid_argument on an unknown mode or a value out of range.
  void Validate() const;
  // Epsilon of actor actor_index of num_actors after `step` steps (epsilon modes).
  double Epsilon(int actor_index, int num_actors, int64_t step) const;
  // Noise scale of actor actor_index of num_actors after `step` steps (gaussian mode).
  double Sigma(int actor_index, int num_actors, int64_t step) const;
};

}  // namespace rl::actor
