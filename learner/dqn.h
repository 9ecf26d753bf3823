// Dqn: the DQN update of Mnih et al. 2015 with the Double DQN target as an option.
//
// Online and target networks, Huber (or MSE) loss on the chosen actions' Q values,
// importance weights, gradient-norm clipping, Adam or RMSProp, and a target network refreshed
// every target_update_period updates with target = tau * online + (1 - tau) * target (tau = 1:
// the hard copy of Mnih et al.; tau < 1 with period 1: Polyak averaging). Knows nothing of LCM.
#pragma once

#include <cstdint>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "envs/env.h"
#include "learner/algorithm.h"
#include "nn/optimizers.h"
#include "nn/sequential.h"

namespace boost::program_options {
class options_description;
}  // namespace boost::program_options

namespace rl::learner {

struct DqnConfig {
  static constexpr const char* kName = "dqn";
  static constexpr const char* kSummary =
      "for discrete actions (Mnih et al. 2015, with Double DQN, dueling, n-step and prioritized "
      "replay)";

  // The Q network: "mlp" (widths in `hidden`), "nature" (Mnih et al. 2015, 4 x 84 x 84 input),
  // "grasp" (stacks of 40 x 40 frames), or an architecture string as nn::BuildFromArchitecture
  // reads it ("conv2d(2,16,3,1,0,10,5),relu,flatten,...").
  std::string network = "mlp";
  std::vector<int> hidden = {120, 84};  // hidden layer widths of the MLP (ReLU between layers)
  bool dueling = false;  // value and advantage streams (Wang et al. 2016); mlp, nature, grasp
  std::string optimizer = "adam";  // "adam" or "rmsprop"
  float learning_rate = 1e-3f;     // step size
  float adam_eps = 1e-8f;          // Adam's epsilon
  float rmsprop_alpha = 0.95f;     // RMSProp smoothing (DeepMind: 0.95)
  float rmsprop_eps = 0.01f;       // RMSProp epsilon (DeepMind: 0.01)
  bool rmsprop_centered = true;    // centered RMSProp, as DeepMind's
  std::string loss = "huber";      // "huber" (delta 1, as Mnih et al.'s error clipping) or "mse"
  bool double_dqn = true;          // pick next actions with the online network
  int target_update_period = 500;  // updates between target refreshes
  float tau = 1.0f;                // weight of the online network in a refresh
  float max_grad_norm = 10.0f;     // global gradient-norm clip (0: none)
  uint64_t seed = 0;               // initialisation seed
  nn::Precision precision = nn::Precision::kFp32;  // the networks' products (nn/precision.h)

  // Throws std::invalid_argument naming the bad field.
  void Validate() const;
  // Adds the options only dqn has, bound to these fields (learner/algorithms.h).
  void AddOptions(boost::program_options::options_description* desc);
  // The algorithm for `spec`. Throws std::invalid_argument when the env's actions do not fit.
  std::unique_ptr<Algorithm> Make(const envs::EnvSpec& spec) const;
};

// The architecture string DqnConfig describes, for observations of obs_size values. Throws
// std::invalid_argument when the network cannot take such observations.
std::string QNetworkArchitecture(const DqnConfig& config, int obs_size, int num_actions);

class Dqn final : public Algorithm {
 public:
  Dqn(int obs_size, int num_actions, DqnConfig config);
  Dqn(const Dqn&) = delete;
  Dqn& operator=(const Dqn&) = delete;

  // One gradient step on the batch (Algorithm::Update).
  UpdateResult Update(const Batch& batch) override;
  const std::vector<float>& last_td_errors() const override { return td_abs_; }
  nn::Sequential& policy() override { return online_; }
  int64_t updates() const override { return updates_; }
  std::string Describe() const override;
  void SetLearningRateScale(float scale) override;
  /// Sections "dqn.online", "dqn.target", "dqn.optimizer", "dqn.updates".
  void SaveState(StateFile* state) const override;
  void LoadState(const StateFile& state) override;

  nn::Sequential& online() { return online_; }
  const nn::Sequential& target() const { return target_; }
  const DqnConfig& config() const { return config_; }

 private:
  DqnConfig config_;
  int obs_size_;
  int num_actions_;
  nn::Sequential online_;
  nn::Sequential target_;
  std::unique_ptr<nn::Optimizer> optimizer_;
  std::vector<nn::Param> params_;
  int64_t updates_ = 0;

  // Buffers reused by every update.
  nn::Matrix grad_q_;
  nn::Vector pred_, target_values_, loss_grad_, weights_;
  std::vector<int> next_actions_;
  std::vector<int> actions_;
  std::vector<float> td_abs_;
};

}  // namespace rl::learner
