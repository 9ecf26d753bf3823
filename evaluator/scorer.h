// Scores a policy by running evaluation episodes, as in Mnih et al. 2015: the greedy action of the
// network with a small exploration rate (epsilon = 0.05), from seeded initial states.
#pragma once

#include <cstdint>
#include <functional>
#include <span>
#include <string>
#include <vector>

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

/// Undiscounted returns of the evaluation episodes and their summary.
struct EvalScore {
  int episodes = 0;
  double mean = 0;  // mean return
  double std = 0;   // population standard deviation of the returns
  double min = 0;
  double max = 0;
  std::vector<double> returns;  // one per episode, in episode order
};

/// Summarizes returns (population std). An empty vector gives an all-zero score.
EvalScore Summarize(std::vector<double> returns);

/// Maps an observation to the greedy action (in [0, num_actions)).
using GreedyPolicy = std::function<int(std::span<const float> observation)>;

/// Runs `episodes` episodes of a fresh `env_id` env: episode i is reset with seed first_seed + i
/// and runs until terminated or truncated. In every step the action is uniform at random with
/// probability `epsilon`, else greedy(observation); the random draws come from a
/// std::mt19937_64 seeded with first_seed, so the same arguments give the same score.
/// Throws std::invalid_argument for episodes < 1, epsilon outside [0, 1], an unknown env id or
/// a greedy action outside the env's action range.
/// `after_episode`, when set, is called after every episode (the evaluator publishes its stats
/// from there, so that a long evaluation does not look like a silent process).
EvalScore ScoreGreedyPolicy(const GreedyPolicy& greedy, const std::string& env_id, int episodes,
                            double epsilon, uint64_t first_seed = kDefaultEvalSeedBase,
                            const std::function<void()>& after_episode = {});

/// ScoreGreedyPolicy with the network's argmax as the greedy action. Throws
/// std::invalid_argument when the network's input or output size does not match the env's
/// observation size or number of actions. The network is used (its scratch buffers) but not
/// changed.
EvalScore ScorePolicy(nn::Sequential* net, const std::string& env_id, int episodes,
                      double epsilon = kDefaultEvalEpsilon,
                      uint64_t first_seed = kDefaultEvalSeedBase,
                      const std::function<void()>& after_episode = {});

/// Empty when a network with these input and output sizes fits the env (input size =
/// observation size, output size = number of actions), else a sentence saying what differs.
std::string CheckNetworkFitsEnv(int input_size, int output_size, const envs::EnvSpec& spec);

}  // namespace rl::evaluator
