// Policies: what turns an observation into an action, for the actors (exploring) and the
// evaluator (exploration off, or the evaluation epsilon), so that the greedy action is computed in
// one place.
//
// An action is EnvSpec::action_width() floats (envs/env.h): for a discrete env one value holding
// the index, for a continuous env the action vector within the bounds.
//
//   EpsilonGreedy  discrete envs, a Q-network (outputs: one value per action): argmax, or a
//                  uniform random action with probability epsilon.
//   GaussianNoise  continuous envs, a deterministic policy network (outputs: the action, already
//                  in the bounds, e.g. ending in nn's bounded layer): mu(s) + N(0, sigma_d^2),
//                  clipped to the bounds, sigma_d = sigma * (high_d - low_d) / 2; uniform random
//                  actions for the first start_steps steps.
//
// Before a network is set, every policy acts uniformly at random. Not thread-safe.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <random>
#include <span>
#include <string>

#include "actor/exploration.h"
#include "envs/env.h"
#include "nn/sequential.h"

namespace rl::actor {

class Policy {
 public:
  virtual ~Policy() = default;

  /// Why `net` cannot drive this policy (input size other than the observation size, output
  /// size other than the number of actions or the action dimension), or empty when it can.
  std::string CheckNetwork(const nn::Sequential& net) const;
  /// Takes `net` (CheckNetwork() must be empty, else std::invalid_argument).
  void SetNetwork(nn::Sequential net);
  bool has_network() const { return has_network_; }
  nn::Sequential& network() { return net_; }

  /// Writes the action for `obs` (observation_size floats) into `action` (action_width floats),
  /// exploring as configured at step `step` of the schedule. No allocation after the first call.
  virtual void Act(std::span<const float> obs, int64_t step, std::span<float> action) = 0;

  /// The network's value estimate of the last action Act() chose (Q(s, a) of a Q-network), or
  /// nothing when the policy has no value estimates (a deterministic actor network) or no network.
  virtual std::optional<double> last_value() const { return std::nullopt; }

  /// The exploration scale at `step`: epsilon, or sigma (1 before start_steps).
  virtual double exploration(int64_t step) const = 0;

  const envs::EnvSpec& spec() const { return spec_; }

 protected:
  Policy(envs::EnvSpec spec, ExplorationConfig config, int actor_index, int num_actors,
         uint64_t seed);

  envs::EnvSpec spec_;
  ExplorationConfig config_;
  int actor_index_;
  int num_actors_;
  nn::Sequential net_;
  bool has_network_ = false;
  std::mt19937_64 rng_;
};

/// The policy for `spec` with `exploration` as actor `actor_index` of `num_actors`, its random
/// draws seeded with `seed`: EpsilonGreedy for a discrete env and an epsilon mode, GaussianNoise
/// for a continuous env and mode "gaussian". Throws std::invalid_argument naming the mismatch
/// for any other pairing (an epsilon mode on a continuous env, or the reverse) and for a bad
/// config.
std::unique_ptr<Policy> MakePolicy(const envs::EnvSpec& spec, const ExplorationConfig& exploration,
                                   int actor_index, int num_actors, uint64_t seed);

/// The exploration of an evaluation: epsilon `epsilon` (constant) for a discrete env; for a
/// continuous one no random start and Gaussian noise of constant `sigma` (0: none, the
/// deterministic policy).
ExplorationConfig EvaluationExploration(const envs::EnvSpec& spec, double epsilon,
                                        double sigma = 0.0);

}  // namespace rl::actor
