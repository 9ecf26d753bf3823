#include "evaluator/scorer.h"

#include <algorithm>
#include <cmath>
#include <random>
#include <stdexcept>
#include <utility>

#include "envs/registry.h"
#include "envs/specs.h"

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

void CheckEpisodes(int episodes) {
  if (episodes < 1) {
    throw std::invalid_argument("episodes must be at least 1, got " + std::to_string(episodes));
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

// The mean of the members' actions.
class MeanAction final : public actor::Policy {
 public:
  MeanAction(const envs::EnvSpec& spec, std::vector<std::unique_ptr<actor::Policy>> members)
      : Policy(spec, actor::EvaluationExploration(spec, 0.0), 0, 1, 0),
        members_(std::move(members)),
        one_(static_cast<size_t>(spec.action_width())) {}

  void Act(std::span<const float> obs, int64_t step, std::span<float> action) override {
    std::fill(action.begin(), action.end(), 0.0f);
    for (const std::unique_ptr<actor::Policy>& member : members_) {
      member->Act(obs, step, one_);
      for (size_t i = 0; i < action.size(); ++i) action[i] += one_[i];
    }
    const auto n = static_cast<float>(members_.size());
    for (float& a : action) a /= n;
  }

  double exploration(int64_t /*step*/) const override { return 0.0; }

 private:
  std::vector<std::unique_ptr<actor::Policy>> members_;
  std::vector<float> one_;
};

}  // namespace

std::unique_ptr<actor::Policy> EnsemblePolicy(const std::vector<nn::Sequential>& nets,
                                              const envs::EnvSpec& spec) {
  if (!spec.continuous()) {
    throw std::invalid_argument(spec.id +
                                " has discrete actions; an ensemble averages continuous ones");
  }
  if (nets.empty()) throw std::invalid_argument("an ensemble needs at least one network");
  std::vector<std::unique_ptr<actor::Policy>> members;
  members.reserve(nets.size());
  for (const nn::Sequential& net : nets) members.push_back(EvaluationPolicy(net, spec, 0.0, 0));
  return std::make_unique<MeanAction>(spec, std::move(members));
}

std::unique_ptr<actor::Policy> EvaluationPolicy(const nn::Sequential& net,
                                                const envs::EnvSpec& spec, double epsilon,
                                                uint64_t seed, double sigma) {
  if (!(epsilon >= 0.0 && epsilon <= 1.0)) {
    throw std::invalid_argument("epsilon must be in [0, 1], got " + std::to_string(epsilon));
  }
  std::unique_ptr<actor::Policy> policy =
      actor::MakePolicy(spec, actor::EvaluationExploration(spec, epsilon, sigma), 0, 1, seed);
  policy->SetNetwork(net);
  return policy;
}

std::string CheckNetworkFitsEnv(const nn::Sequential& net, const envs::EnvSpec& spec) {
  return actor::MakePolicy(spec, actor::EvaluationExploration(spec, 0.0), 0, 1, 0)
      ->CheckNetwork(net);
}

EvalScore Score(actor::Policy* policy, const std::string& env_id, int episodes, uint64_t first_seed,
                double gamma, const std::function<void()>& tick) {
  CheckEpisodes(episodes);
  if (!(gamma >= 0.0 && gamma <= 1.0)) {
    throw std::invalid_argument("gamma must be in [0, 1], got " + std::to_string(gamma));
  }
  std::unique_ptr<envs::Env> env = envs::MakeEnv(env_id);
  std::vector<float> action(static_cast<size_t>(env->spec().action_width()));
  CalibrationAccumulator calibration(gamma);
  bool has_values = false;

  std::vector<double> returns;
  std::vector<int> steps;
  const bool continuous = env->spec().continuous();
  std::vector<double> action_sum(continuous ? action.size() : 0, 0.0);
  int64_t total_steps = 0;
  returns.reserve(static_cast<size_t>(episodes));
  steps.reserve(static_cast<size_t>(episodes));
  for (int i = 0; i < episodes; ++i) {
    env->Reset(first_seed + static_cast<uint64_t>(i));
    double episode_return = 0;
    int episode_steps = 0;
    // Act until the env terminates or its time limit truncates the episode.
    for (;;) {
      policy->Act(env->observation(), 0, action);
      // The value of the action taken, random ones included (a Q-network's estimate).
      const std::optional<double> value = policy->last_value();
      const envs::StepResult step = env->Step(action);
      episode_return += step.reward;
      ++episode_steps;
      for (size_t d = 0; d < action_sum.size(); ++d) action_sum[d] += action[d];
      if (value) {
        has_values = true;
        calibration.Step(*value, step.reward);
      }
      if (tick) tick();
      if (step.terminated || step.truncated) {
        if (has_values) calibration.EndEpisode(step.terminated);
        break;
      }
    }
    returns.push_back(episode_return);
    steps.push_back(episode_steps);
    total_steps += episode_steps;
  }
  EvalScore score = Summarize(std::move(returns));
  score.steps = std::move(steps);
  for (double sum : action_sum) {
    score.action_mean.push_back(total_steps > 0 ? sum / static_cast<double>(total_steps) : 0.0);
  }
  if (has_values) score.values = calibration.Result();
  return score;
}

EvalScore ScorePolicy(nn::Sequential* net, const std::string& env_id, int episodes, double epsilon,
                      uint64_t first_seed, double gamma, const std::function<void()>& tick,
                      double sigma) {
  std::unique_ptr<actor::Policy> policy =
      EvaluationPolicy(*net, envs::LookupSpec(env_id), epsilon, first_seed, sigma);
  return Score(policy.get(), env_id, episodes, first_seed, gamma, tick);
}

}  // namespace rl::evaluator
