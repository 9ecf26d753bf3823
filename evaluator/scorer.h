// Scores a policy by running evaluation episodes from seeded initial states: for a Q-network, as
// in Mnih et al. 2015, the greedy action with a small exploration rate (epsilon = 0.05); for a
// TD3 actor, its deterministic action (Fujimoto et al. 2018 evaluate without noise).
#pragma once

#include <cstdint>
#include <functional>
#include <limits>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "actor/policy.h"
#include "envs/env.h"
#include "nn/sequential.h"

namespace rl::evaluator {

/// First episode seed of an evaluation. Episode i is reset with seed kDefaultEvalSeedBase + i.
/// Actors seed their envs with small numbers (run seed plus actor index), so evaluation episodes
/// start from initial states that training never saw seeded, and every checkpoint is scored on
/// the same episodes (a fair comparison between checkpoints).
inline constexpr uint64_t kDefaultEvalSeedBase = 1'000'000'000;

/// Exploration rate while scoring, as in Mnih et al. 2015 (it keeps a policy that found a loop
/// in the env's dynamics from scoring on a single lucky trajectory).
inline constexpr double kDefaultEvalEpsilon = 0.05;

/// Discount of the value estimates: the actors' default (a run's evaluator must use its actors').
inline constexpr double kDefaultGamma = 0.99;

/// A step of an episode cut by its time limit counts in a ValueCalibration only while the part of
/// the return after the cut, which nobody saw, weighs at most this much (gamma^k <= 0.01).
inline constexpr double kUnseenTailWeight = 0.01;

/// How a Q-network's value estimates compare with the returns that actually followed, as in van
/// Hasselt et al. (2016): for every step t of the evaluation, Q(s_t, a_t) of the action taken
/// against the discounted return sum_k gamma^k r_{t+k} to the end of the episode.
struct ValueCalibration {
  int64_t steps = 0;                                              // steps compared
  double estimate = 0;                                            // mean Q(s_t, a_t)
  double actual = 0;                                              // mean discounted return from s_t
  double correlation = std::numeric_limits<double>::quiet_NaN();  // Pearson, across the steps;
                                                                  // NaN when either is constant
};

/// Undiscounted returns of the evaluation episodes and their summary.
struct EvalScore {
  int episodes = 0;
  double mean = 0;  // mean return
  double std = 0;   // population standard deviation of the returns
  double min = 0;
  double max = 0;
  std::vector<double> returns;  // one per episode, in episode order
  std::vector<int> steps;       // each episode's env steps (Score() only), in episode order
  // Continuous actions (Score() only): each component's mean over every step, as the policy gave
  // it.
  std::vector<double> action_mean;
  /// Set when the policy gave value estimates (a Q network's, see Policy::last_value) and some
  /// steps could be compared.
  std::optional<ValueCalibration> values;
};

/// Summarizes returns (population std). An empty vector gives an all-zero score.
EvalScore Summarize(std::vector<double> returns);

/// Pearson correlation of two equally long series; NaN when they are shorter than 2 or either
/// is constant.
double Correlation(std::span<const double> x, std::span<const double> y);

/// The evaluation policy of `net` for `spec` (actor/policy.h): the greedy action of a Q-network
/// with a uniform random action with probability `epsilon` (discrete envs), or the actor
/// network's action without noise (continuous envs; with `sigma` > 0, the actors' Gaussian noise
/// at a constant sigma, for comparing the noisy policy with the deterministic one); random
/// draws seeded with `seed`. Throws std::invalid_argument when the network does not fit the env
/// or epsilon is outside [0, 1].
std::unique_ptr<actor::Policy> EvaluationPolicy(const nn::Sequential& net,
                                                const envs::EnvSpec& spec, double epsilon,
                                                uint64_t seed, double sigma = 0.0);

/// The mean action of the deterministic policies of `nets` (EvaluationPolicy without noise) for
/// a continuous env: an ensemble of checkpoints of one run, each network run on every
/// observation. Throws std::invalid_argument for a discrete env, no network, or a network that
/// does not fit the env.
std::unique_ptr<actor::Policy> EnsemblePolicy(const std::vector<nn::Sequential>& nets,
                                              const envs::EnvSpec& spec);

/// Runs `episodes` episodes of a fresh `env_id` env with `policy` (step 0 of its schedule): episode
/// i is reset with seed first_seed + i and runs until terminated or truncated. When the policy
/// gives value estimates (a Q-network), the value of every action taken is compared with the
/// discounted return (discount `gamma`) that followed it (EvalScore::values). Throws
/// std::invalid_argument for episodes < 1, gamma outside [0, 1] or an unknown env id.
/// `tick`, when set, is called after every step (the evaluator publishes its stats from there,
/// so that a long evaluation does not look like a silent process; progress.h).
EvalScore Score(actor::Policy* policy, const std::string& env_id, int episodes,
                uint64_t first_seed = kDefaultEvalSeedBase, double gamma = kDefaultGamma,
                const std::function<void()>& tick = {});

/// Score() with EvaluationPolicy(*net, env's spec, epsilon, first_seed, sigma). The network is
/// copied, not changed.
EvalScore ScorePolicy(nn::Sequential* net, const std::string& env_id, int episodes,
                      double epsilon = kDefaultEvalEpsilon,
                      uint64_t first_seed = kDefaultEvalSeedBase, double gamma = kDefaultGamma,
                      const std::function<void()>& tick = {}, double sigma = 0.0);

/// Empty when `net` can drive a policy of `spec` (input size = observation size, output size =
/// number of actions or action dimension), else a sentence saying what differs.
std::string CheckNetworkFitsEnv(const nn::Sequential& net, const envs::EnvSpec& spec);

}  // namespace rl::evaluator
