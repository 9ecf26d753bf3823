// Td3: Twin Delayed DDPG (Fujimoto, van Hoof, Meger 2018) for continuous actions.
//
// A deterministic actor mu(s) (ending in the action bounds) and two critics Q1, Q2 (s, a) -> 1,
// each with a Polyak-averaged target. Per update:
//   a' = clip(mu_target(s') + clip(N(0, (target_noise * h)^2), -target_noise_clip * h,
//                                  target_noise_clip * h), low, high),  h = (high - low) / 2
//   y  = r + discount * min(Q1_target(s', a'), Q2_target(s', a'))       (clipped double-Q)
//   critic loss = mean_i w_i (Q1(s_i, a_i) - y_i)^2 + mean_i w_i (Q2(s_i, a_i) - y_i)^2
// and every policy_delay-th update also
//   actor loss = -mean_i Q1(s_i, mu(s_i))     (its gradient through Q1's action input)
//   targets    = tau * online + (1 - tau) * target, for the actor and both critics.
// `discount` comes with the batch (gamma^k for n-step returns, 0 after a termination, gamma^k
// after a time-limit truncation: truncations are bootstrapped), and w are the importance weights
// of prioritized replay (1 for uniform). The critics and the actor have their own Adam optimizers
// and learning rates. Knows nothing of LCM.
//
// With network "drq" (DrQ-v2's practice, Yarats et al. 2021) one CNN encoder is shared: the
// critics and the actor are heads on its features, the encoder is trained by the critics' loss
// only (the actor and the targets see its features as constants), and s' is encoded by the same
// online encoder. The encoder then runs forward twice and backward once per update instead of
// three networks' encoders with their targets, about a third of the work.
#pragma once

#include <cstdint>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "envs/env.h"
#include "learner/algorithm.h"
#include "nn/action_value_net.h"
#include "nn/optimizers.h"
#include "nn/sequential.h"

namespace boost::program_options {
class options_description;
}  // namespace boost::program_options

namespace rl::learner {

struct Td3Config {
  static constexpr const char* kName = "td3";
  static constexpr const char* kSummary =
      "for continuous actions (Twin Delayed DDPG, Fujimoto et al. 2018)";

  // The networks: "mlp" (actor obs -> hidden... -> action, critics [obs, action] -> hidden... ->
  // 1; the author's 256-256), "car" (the TD3 CarRacing article's networks on 4 x 84 x 84 stacks:
  // a CNN encoder of its own in the actor and in each critic) or "drq" (the article's encoder,
  // shared, with DrQ-v2's heads of width hidden[0]; see the top of this file).
  std::string network = "mlp";
  std::vector<int> hidden = {256, 256};
  float actor_learning_rate = 3e-4f;
  float critic_learning_rate = 3e-4f;
  float adam_eps = 1e-8f;
  float tau = 0.005f;              // Polyak weight of the online networks
  int policy_delay = 2;            // critic updates per actor and target update
  float target_noise = 0.2f;       // target policy smoothing, relative to the half-range
  float target_noise_clip = 0.5f;  // its clip, relative to the half-range
  float max_grad_norm = 0.0f;      // global gradient-norm clip of each optimizer (0: none)
  uint64_t seed = 0;               // initialisation and target-noise seed
  nn::Precision precision = nn::Precision::kFp32;  // the networks' products (nn/precision.h)
  // Network drq: the shared encoder's products when they differ from `precision` ("fp32" or
  // "bf16"; empty: `precision`), e.g. bf16 convolutions beside fp32 heads.
  std::string encoder_precision;

  // Throws std::invalid_argument naming the bad field.
  void Validate() const;
  // Adds the options only td3 has, bound to these fields (learner/algorithms.h).
  void AddOptions(boost::program_options::options_description* desc);
  // The algorithm for `spec`. Throws std::invalid_argument when the env's actions do not fit.
  std::unique_ptr<Algorithm> Make(const envs::EnvSpec& spec) const;
};

/// The actor's architecture string for `spec` (nn::BuildFromArchitecture), and the critics'
/// (nn::BuildActionValueNet). Throw std::invalid_argument when the network cannot take the env.
std::string Td3ActorArchitecture(const Td3Config& config, const envs::EnvSpec& spec);
std::string Td3CriticArchitecture(const Td3Config& config, const envs::EnvSpec& spec);

class Td3 final : public Algorithm {
 public:
  /// Throws std::invalid_argument for a bad config or a discrete env.
  Td3(const envs::EnvSpec& spec, Td3Config config);
  Td3(const Td3&) = delete;
  Td3& operator=(const Td3&) = delete;

  UpdateResult Update(const Batch& batch) override;
  const std::vector<float>& last_td_errors() const override { return td_abs_; }
  /// The actor; with a shared encoder, the encoder followed by the actor head (refreshed here).
  nn::Sequential& policy() override;
  int64_t updates() const override { return updates_; }
  std::string Describe() const override;
  void SetLearningRateScale(float scale) override;
  /// Sections "td3.*": the actor, both critics and their targets (and the shared encoder), both
  /// optimizers, the update counters and the target-noise generator.
  void SaveState(StateFile* state) const override;
  void LoadState(const StateFile& state) override;

  /// Actor updates so far (one per policy_delay critic updates).
  int64_t actor_updates() const { return actor_updates_; }
  /// The actor (with a shared encoder: the head on its features).
  nn::Sequential& actor() { return actor_; }
  /// Whether the encoder is shared (network "drq"), and the encoder then.
  bool shared_encoder() const { return shared_encoder_; }
  nn::Sequential& encoder() { return encoder_; }
  const nn::Sequential& actor_target() const { return actor_target_; }
  nn::ActionValueNet& critic(int i) { return i == 0 ? q1_ : q2_; }
  const nn::ActionValueNet& critic_target(int i) const { return i == 0 ? q1_target_ : q2_target_; }
  /// The targets y of the last Update.
  const nn::Vector& last_targets() const { return y_; }
  const Td3Config& config() const { return config_; }

 private:
  // Fills next_action_ with the smoothed target action for next_obs.
  void TargetActions(const nn::Matrix& next_obs);

  envs::EnvSpec spec_;
  Td3Config config_;
  int action_dim_;
  bool shared_encoder_ = false;
  nn::Sequential encoder_;  // network "drq" only
  nn::Sequential policy_;   // network "drq" only: encoder + actor head, filled by policy()
  nn::Sequential actor_, actor_target_;
  nn::ActionValueNet q1_, q2_, q1_target_, q2_target_;
  std::vector<nn::Param> actor_params_, critic_params_;
  std::unique_ptr<nn::Adam> actor_optimizer_, critic_optimizer_;
  std::mt19937_64 noise_rng_;
  std::normal_distribution<float> normal_{0.0f, 1.0f};
  int64_t updates_ = 0;
  int64_t actor_updates_ = 0;

  // Buffers reused by every update. The two critics' passes run side by side (Update), each with
  // its own prediction, loss gradient and dQ: index 0 for q1, 1 for q2.
  nn::Matrix action_, next_action_, grad_actor_;
  nn::Matrix grad_q_[2];
  nn::Matrix features_, next_features_, grad_features_;  // shared encoder only
  std::vector<float> flat_, head_flat_;
  nn::Vector y_, weights_;
  nn::Vector q_pred_[2], loss_grad_[2];
  std::vector<float> td_abs_;
};

}  // namespace rl::learner
