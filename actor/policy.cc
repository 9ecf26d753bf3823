#include "actor/policy.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <utility>
#include <vector>

namespace rl::actor {
namespace {

class EpsilonGreedy final : public Policy {
 public:
  EpsilonGreedy(envs::EnvSpec spec, ExplorationConfig config, int actor_index, int num_actors,
                uint64_t seed)
      : Policy(std::move(spec), std::move(config), actor_index, num_actors, seed),
        random_action_(0, spec_.num_actions - 1) {}

  void Act(std::span<const float> obs, int64_t step, std::span<float> action) override {
    value_.reset();
    const double epsilon = exploration(step);
    // The coin is drawn first, so that a policy's random stream does not depend on whether it
    // has a network.
    const bool random = unit_(rng_) < epsilon;
    if (!has_network_) {
      action[0] = static_cast<float>(random_action_(rng_));
      return;
    }
    const nn::Matrix& q = net_.Predict(obs.data(), static_cast<int>(obs.size()));
    int a = 0;
    if (random) {
      a = random_action_(rng_);
    } else {
      q.col(0).maxCoeff(&a);
    }
    value_ = static_cast<double>(q(a, 0));
    action[0] = static_cast<float>(a);
  }

  std::optional<double> last_value() const override { return value_; }

  double exploration(int64_t step) const override {
    return config_.Epsilon(actor_index_, num_actors_, step);
  }

 private:
  std::uniform_real_distribution<double> unit_{0.0, 1.0};
  std::uniform_int_distribution<int> random_action_;
  std::optional<double> value_;
};

class GaussianNoise final : public Policy {
 public:
  GaussianNoise(envs::EnvSpec spec, ExplorationConfig config, int actor_index, int num_actors,
                uint64_t seed)
      : Policy(std::move(spec), std::move(config), actor_index, num_actors, seed) {}

  void Act(std::span<const float> obs, int64_t step, std::span<float> action) override {
    const size_t n = action.size();
    if (!has_network_ || step < config_.start_steps) {
      for (size_t d = 0; d < n; ++d) {
        action[d] =
            std::uniform_real_distribution<float>(spec_.action_low[d], spec_.action_high[d])(rng_);
      }
      return;
    }
    const nn::Matrix& mu = net_.Predict(obs.data(), static_cast<int>(obs.size()));
    const double sigma = exploration(step);
    for (size_t d = 0; d < n; ++d) {
      const float low = spec_.action_low[d];
      const float high = spec_.action_high[d];
      float a = mu(static_cast<Eigen::Index>(d), 0);
      if (sigma > 0) a += static_cast<float>(sigma * (high - low) / 2 * normal_(rng_));
      action[d] = std::clamp(a, low, high);
    }
  }

  double exploration(int64_t step) const override {
    if (step < config_.start_steps) return 1.0;
    return config_.Sigma(actor_index_, num_actors_, step);
  }

 private:
  std::normal_distribution<double> normal_{0.0, 1.0};
};

}  // namespace

Policy::Policy(envs::EnvSpec spec, ExplorationConfig config, int actor_index, int num_actors,
               uint64_t seed)
    : spec_(std::move(spec)),
      config_(std::move(config)),
      actor_index_(actor_index),
      num_actors_(num_actors),
      rng_(seed) {}

std::string Policy::CheckNetwork(const nn::Sequential& net) const {
  const int outputs = spec_.continuous() ? spec_.action_dim : spec_.num_actions;
  const char* what = spec_.continuous() ? "action dimensions" : "actions";
  std::string why;
  if (net.InputSize() != spec_.observation_size) {
    why = "network input size " + std::to_string(net.InputSize()) + " does not match " + spec_.id +
          "'s observation size " + std::to_string(spec_.observation_size);
  }
  if (net.OutputSize() != outputs) {
    if (!why.empty()) why += "; ";
    why += "network output size " + std::to_string(net.OutputSize()) + " does not match " +
           spec_.id + "'s " + std::to_string(outputs) + " " + what;
    // CarRacing's two action forms differ by the env string alone: name the option.
    if (spec_.id == "CarRacing-v3" && net.OutputSize() == 3) {
      why += " (a network for gas and brake as two actions: drop pedals=1 from the env)";
    } else if (spec_.id == "CarRacing-v3" && net.OutputSize() == 2) {
      why += " (a network for steer and one pedal: add pedals=1 to the env)";
    }
  }
  return why;
}

void Policy::SetNetwork(nn::Sequential net) {
  const std::string why = CheckNetwork(net);
  if (!why.empty()) throw std::invalid_argument(why);
  net_ = std::move(net);
  has_network_ = true;
}

std::unique_ptr<Policy> MakePolicy(const envs::EnvSpec& spec, const ExplorationConfig& exploration,
                                   int actor_index, int num_actors, uint64_t seed) {
  exploration.Validate();
  if (spec.continuous() && !exploration.gaussian()) {
    throw std::invalid_argument(spec.id + " has continuous actions; exploration '" +
                                exploration.mode +
                                "' is epsilon-greedy, for discrete ones (use gaussian)");
  }
  if (!spec.continuous() && exploration.gaussian()) {
    throw std::invalid_argument(spec.id +
                                " has discrete actions; gaussian exploration is for continuous "
                                "ones (use apex, linear or constant)");
  }
  if (spec.continuous()) {
    return std::make_unique<GaussianNoise>(spec, exploration, actor_index, num_actors, seed);
  }
  return std::make_unique<EpsilonGreedy>(spec, exploration, actor_index, num_actors, seed);
}

ExplorationConfig EvaluationExploration(const envs::EnvSpec& spec, double epsilon, double sigma) {
  ExplorationConfig c;
  if (spec.continuous()) {
    c.mode = "gaussian";
    c.sigma = c.sigma_end = sigma;
    c.start_steps = 0;
  } else {
    c.mode = "constant";
    c.end = epsilon;
  }
  return c;
}

}  // namespace rl::actor
