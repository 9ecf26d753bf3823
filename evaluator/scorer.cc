#include "evaluator/scorer.h"

#include <algorithm>
#include <cmath>
#include <random>
#include <stdexcept>
#include <utility>

#include "envs/registry.h"

namespace rl::evaluator {

EvalScore Summarize(std::vector<double> returns) {
  EvalScore s;
  s.episodes = static_cast<int>(returns.size());
  if (!returns.empty()) {
    double sum = 0;
    for (double r : returns) sum += r;
    s.mean = sum / static_cast<double>(returns.size());
    double sq = 0;
    for (double r : returns) sq += (r - s.mean) * (r - s.mean);
    s.std = std::sqrt(sq / static_cast<double>(returns.size()));
    const auto [lo, hi] = std::minmax_element(returns.begin(), returns.end());
    s.min = *lo;
    s.max = *hi;
  }
  s.returns = std::move(returns);
  return s;
}

EvalScore ScoreGreedyPolicy(const GreedyPolicy& greedy, const std::string& env_id, int episodes,
                            double epsilon, uint64_t first_seed,
                            const std::function<void()>& after_episode) {
  if (episodes < 1) {
    throw std::invalid_argument("episodes must be at least 1, got " + std::to_string(episodes));
  }
  if (!(epsilon >= 0.0 && epsilon <= 1.0)) {
    throw std::invalid_argument("epsilon must be in [0, 1], got " + std::to_string(epsilon));
  }
  std::unique_ptr<envs::Env> env = envs::MakeEnv(env_id);
  const int num_actions = env->spec().num_actions;
  std::mt19937_64 rng(first_seed);
  std::uniform_real_distribution<double> coin(0.0, 1.0);
  std::uniform_int_distribution<int> random_action(0, num_actions - 1);

  std::vector<double> returns;
  returns.reserve(static_cast<size_t>(episodes));
  for (int i = 0; i < episodes; ++i) {
    env->Reset(first_seed + static_cast<uint64_t>(i));
    double episode_return = 0;
    // Act until the env terminates or its time limit truncates the episode.
    for (;;) {
      int action;
      if (epsilon > 0.0 && coin(rng) < epsilon) {
        action = random_action(rng);
      } else {
        action = greedy(env->observation());
        if (action < 0 || action >= num_actions) {
          throw std::invalid_argument("greedy action " + std::to_string(action) + " outside [0, " +
                                      std::to_string(num_actions) + ")");
        }
      }
      const envs::StepResult step = env->Step(action);
      episode_return += step.reward;
      if (step.terminated || step.truncated) break;
    }
    returns.push_back(episode_return);
    if (after_episode) after_episode();
  }
  return Summarize(std::move(returns));
}

std::string CheckNetworkFitsEnv(int input_size, int output_size, const envs::EnvSpec& spec) {
  if (spec.action_dim > 0) {
    return spec.id + " has continuous actions; a Q-network scores discrete ones only";
  }
  std::string why;
  if (input_size != spec.observation_size) {
    why = "network input size " + std::to_string(input_size) + " does not match " + spec.id +
          "'s observation size " + std::to_string(spec.observation_size);
  }
  if (output_size != spec.num_actions) {
    if (!why.empty()) why += "; ";
    why += "network output size " + std::to_string(output_size) + " does not match " + spec.id +
           "'s " + std::to_string(spec.num_actions) + " actions";
  }
  return why;
}

EvalScore ScorePolicy(nn::Sequential* net, const std::string& env_id, int episodes, double epsilon,
                      uint64_t first_seed, const std::function<void()>& after_episode) {
  const std::string why =
      CheckNetworkFitsEnv(net->InputSize(), net->OutputSize(), envs::MakeEnv(env_id)->spec());
  if (!why.empty()) throw std::invalid_argument(why);
  const GreedyPolicy greedy = [net](std::span<const float> obs) {
    return net->Argmax(obs.data(), static_cast<int>(obs.size()));
  };
  return ScoreGreedyPolicy(greedy, env_id, episodes, epsilon, first_seed, after_episode);
}

}  // namespace rl::evaluator
