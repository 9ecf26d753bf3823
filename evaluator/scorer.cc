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

double Correlation(std::span<const double> x, std::span<const double> y) {
  const std::size_t n = std::min(x.size(), y.size());
  if (n < 2) return std::nan("");
  double mx = 0, my = 0;
  for (std::size_t i = 0; i < n; ++i) {
    mx += x[i];
    my += y[i];
  }
  mx /= static_cast<double>(n);
  my /= static_cast<double>(n);
  double sxx = 0, syy = 0, sxy = 0;
  for (std::size_t i = 0; i < n; ++i) {
    sxx += (x[i] - mx) * (x[i] - mx);
    syy += (y[i] - my) * (y[i] - my);
    sxy += (x[i] - mx) * (y[i] - my);
  }
  if (!(sxx > 0) || !(syy > 0)) return std::nan("");
  return sxy / std::sqrt(sxx * syy);
}

namespace {

void CheckArguments(int episodes, double epsilon) {
  if (episodes < 1) {
    throw std::invalid_argument("episodes must be at least 1, got " + std::to_string(episodes));
  }
  if (!(epsilon >= 0.0 && epsilon <= 1.0)) {
    throw std::invalid_argument("epsilon must be in [0, 1], got " + std::to_string(epsilon));
  }
}

// The value estimates of the steps scored so far and the discounted returns that followed.
class CalibrationAccumulator {
 public:
  explicit CalibrationAccumulator(double gamma) : gamma_(gamma) {}

  void Step(double value, double reward) {
    values_.push_back(value);
    rewards_.push_back(reward);
  }

  // Ends the episode: every step of a terminated one counts; of a truncated one, the steps whose
  // unseen rest of the return weighs at most kUnseenTailWeight.
  void EndEpisode(bool terminated) {
    double g = 0;
    double tail = 1;  // gamma^(steps from t to the end of the episode)
    for (std::size_t t = rewards_.size(); t-- > 0;) {
      g = rewards_[t] + gamma_ * g;
      tail *= gamma_;
      if (terminated || tail <= kUnseenTailWeight) {
        estimates_.push_back(values_[t]);
        returns_.push_back(g);
      }
    }
    values_.clear();
    rewards_.clear();
  }

  std::optional<ValueCalibration> Result() const {
    if (estimates_.empty()) return std::nullopt;
    ValueCalibration c;
    c.steps = static_cast<int64_t>(estimates_.size());
    for (std::size_t i = 0; i < estimates_.size(); ++i) {
      c.estimate += estimates_[i];
      c.actual += returns_[i];
    }
    c.estimate /= static_cast<double>(c.steps);
    c.actual /= static_cast<double>(c.steps);
    c.correlation = Correlation(estimates_, returns_);
    return c;
  }

 private:
  double gamma_;
  std::vector<double> values_, rewards_;     // the current episode
  std::vector<double> estimates_, returns_;  // the steps that count, all episodes
};

// Plays the episodes of ScoreGreedyPolicy; with `values`, the greedy action is the first largest
// value and the values of the actions taken are compared with the returns (discount gamma).
EvalScore Play(const GreedyPolicy& greedy, const ActionValues& values, double gamma,
               const std::string& env_id, int episodes, double epsilon, uint64_t first_seed,
               const std::function<void()>& after_episode) {
  CheckArguments(episodes, epsilon);
  std::unique_ptr<envs::Env> env = envs::MakeEnv(env_id);
  const int num_actions = env->spec().num_actions;
  std::mt19937_64 rng(first_seed);
  std::uniform_real_distribution<double> coin(0.0, 1.0);
  std::uniform_int_distribution<int> random_action(0, num_actions - 1);
  CalibrationAccumulator calibration(gamma);

  std::vector<double> returns;
  returns.reserve(static_cast<size_t>(episodes));
  for (int i = 0; i < episodes; ++i) {
    env->Reset(first_seed + static_cast<uint64_t>(i));
    double episode_return = 0;
    // Act until the env terminates or its time limit truncates the episode.
    for (;;) {
      const bool explore = epsilon > 0.0 && coin(rng) < epsilon;
      // The values are asked for on random steps too: the random action's value is compared.
      std::span<const float> q;
      if (values) {
        q = values(env->observation());
        if (static_cast<int>(q.size()) != num_actions) {
          throw std::invalid_argument(std::to_string(q.size()) + " action values for " +
                                      std::to_string(num_actions) + " actions");
        }
      }
      int action;
      if (explore) {
        action = random_action(rng);
      } else if (values) {
        action = static_cast<int>(std::max_element(q.begin(), q.end()) - q.begin());
      } else {
        action = greedy(env->observation());
        if (action < 0 || action >= num_actions) {
          throw std::invalid_argument("greedy action " + std::to_string(action) + " outside [0, " +
                                      std::to_string(num_actions) + ")");
        }
      }
      const double value = values ? static_cast<double>(q[static_cast<size_t>(action)]) : 0.0;
      const envs::StepResult step = env->Step(action);
      episode_return += step.reward;
      if (values) calibration.Step(value, step.reward);
      if (step.terminated || step.truncated) {
        if (values) calibration.EndEpisode(step.terminated);
        break;
      }
    }
    returns.push_back(episode_return);
    if (after_episode) after_episode();
  }
  EvalScore score = Summarize(std::move(returns));
  if (values) score.values = calibration.Result();
  return score;
}

}  // namespace

EvalScore ScoreGreedyPolicy(const GreedyPolicy& greedy, const std::string& env_id, int episodes,
                            double epsilon, uint64_t first_seed,
                            const std::function<void()>& after_episode) {
  return Play(greedy, ActionValues(), kDefaultGamma, env_id, episodes, epsilon, first_seed,
              after_episode);
}

EvalScore ScoreActionValues(const ActionValues& values, const std::string& env_id, int episodes,
                            double epsilon, double gamma, uint64_t first_seed,
                            const std::function<void()>& after_episode) {
  if (!(gamma >= 0.0 && gamma <= 1.0)) {
    throw std::invalid_argument("gamma must be in [0, 1], got " + std::to_string(gamma));
  }
  return Play(GreedyPolicy(), values, gamma, env_id, episodes, epsilon, first_seed, after_episode);
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
                      uint64_t first_seed, double gamma,
                      const std::function<void()>& after_episode) {
  const std::string why =
      CheckNetworkFitsEnv(net->InputSize(), net->OutputSize(), envs::MakeEnv(env_id)->spec());
  if (!why.empty()) throw std::invalid_argument(why);
  const ActionValues values = [net](std::span<const float> obs) {
    const nn::Matrix& q = net->Predict(obs.data(), static_cast<int>(obs.size()));
    return std::span<const float>(q.data(), static_cast<size_t>(q.size()));
  };
  return ScoreActionValues(values, env_id, episodes, epsilon, gamma, first_seed, after_episode);
}

}  // namespace rl::evaluator
