#include "learner/td3.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "common/options.h"
#include "learner/algorithm_state.h"
#include "nn/losses.h"
#include "nn/parallel.h"
#include "nn/presets.h"

namespace rl::learner {
namespace {

std::string Widths(const std::vector<int>& hidden) {
  std::string s;
  for (int h : hidden) {
    if (!s.empty()) s += '-';
    s += std::to_string(h);
  }
  return s;
}

void CheckContinuous(const envs::EnvSpec& spec) {
  if (!spec.continuous()) {
    throw std::invalid_argument(spec.id +
                                " has discrete actions; TD3 needs continuous ones (use "
                                "algorithm = dqn)");
  }
}

}  // namespace

void Td3Config::Validate() const {
  if (network != "mlp" && network != "car" && network != "drq") {
    throw std::invalid_argument("td3 network must be mlp, car or drq, not '" + network + "'");
  }
  if (hidden.empty()) throw std::invalid_argument("hidden: at least one hidden layer");
  for (int h : hidden) {
    if (h < 1) throw std::invalid_argument("hidden: widths must be >= 1");
  }
  if (!(actor_learning_rate > 0)) throw std::invalid_argument("actor-learning-rate must be > 0");
  if (!(critic_learning_rate > 0)) throw std::invalid_argument("critic-learning-rate must be > 0");
  if (!(adam_eps >= 0)) throw std::invalid_argument("adam-eps must be >= 0");
  if (!(tau > 0 && tau <= 1)) throw std::invalid_argument("tau must be in (0, 1]");
  if (policy_delay < 1) throw std::invalid_argument("policy-delay must be >= 1");
  if (!(target_noise >= 0 && std::isfinite(target_noise))) {
    throw std::invalid_argument("target-noise must be >= 0");
  }
  if (!(target_noise_clip >= 0 && std::isfinite(target_noise_clip))) {
    throw std::invalid_argument("target-noise-clip must be >= 0");
  }
  if (!(max_grad_norm >= 0)) throw std::invalid_argument("max-grad-norm must be >= 0");
  if (!encoder_precision.empty()) {
    if (encoder_precision != "fp32" && encoder_precision != "bf16") {
      throw std::invalid_argument("encoder-precision must be fp32 or bf16, not '" +
                                  encoder_precision + "'");
    }
    if (network != "drq") {
      throw std::invalid_argument("encoder-precision is for network drq (a shared encoder), not '" +
                                  network + "'");
    }
  }
}

void Td3Config::AddOptions(po::options_description* desc) {
  desc->add_options()  //
      ("actor-learning-rate", po::value(&actor_learning_rate)->default_value(actor_learning_rate),
       "the actor's Adam step size")  //
      ("critic-learning-rate",
       po::value(&critic_learning_rate)->default_value(critic_learning_rate),
       "the critics' Adam step size")  //
      ("policy-delay", po::value(&policy_delay)->default_value(policy_delay),
       "critic updates per actor and target update")  //
      ("target-noise", po::value(&target_noise)->default_value(target_noise),
       "target policy smoothing noise, relative to each action dimension's half-range")  //
      ("target-noise-clip", po::value(&target_noise_clip)->default_value(target_noise_clip),
       "clip of that noise, relative to the half-range")  //
      ("encoder-precision", po::value(&encoder_precision),
       "network drq: the shared encoder's matrix products, fp32 or bf16, where they should "
       "differ from --precision, which the heads keep (default: --precision)");
}

std::unique_ptr<Algorithm> Td3Config::Make(const envs::EnvSpec& spec) const {
  return std::make_unique<Td3>(spec, *this);
}

namespace {

void CheckCarInput(const Td3Config& config, const envs::EnvSpec& spec) {
  if (spec.observation_size != 4 * 84 * 84) {
    throw std::invalid_argument("td3 network '" + config.network +
                                "' takes 4 x 84 x 84 observations; " + spec.id + " has " +
                                std::to_string(spec.observation_size) + " values");
  }
}

}  // namespace

std::string Td3ActorArchitecture(const Td3Config& config, const envs::EnvSpec& spec) {
  CheckContinuous(spec);
  if (config.network == "car") {
    CheckCarInput(config, spec);
    return nn::Td3CarActorArchitecture(spec.action_low, spec.action_high);
  }
  if (config.network == "drq") {
    CheckCarInput(config, spec);
    return nn::CarEncoderArchitecture() + "," +
           nn::DrqActorHeadArchitecture(config.hidden.front(), spec.action_low, spec.action_high);
  }
  return nn::Td3MlpActorArchitecture(spec.observation_size, config.hidden, spec.action_low,
                                     spec.action_high);
}

std::string Td3CriticArchitecture(const Td3Config& config, const envs::EnvSpec& spec) {
  CheckContinuous(spec);
  if (config.network == "car") {
    if (spec.observation_size != 4 * 84 * 84 || spec.action_dim != 3) {
      throw std::invalid_argument(
          "td3 network 'car' takes 4 x 84 x 84 observations and 3-d "
          "actions");
    }
    return nn::Td3CarCriticArchitecture();
  }
  if (config.network == "drq") {
    CheckCarInput(config, spec);
    return nn::DrqCriticHeadArchitecture(config.hidden.front(), spec.action_dim);
  }
  return nn::Td3MlpCriticArchitecture(spec.observation_size, spec.action_dim, config.hidden);
}

namespace {

nn::Sequential BuildActor(const Td3Config& config, const envs::EnvSpec& spec, std::mt19937* rng) {
  config.Validate();
  return nn::BuildFromArchitecture(Td3ActorArchitecture(config, spec), rng);
}

nn::ActionValueNet BuildCritic(const Td3Config& config, const envs::EnvSpec& spec,
                               std::mt19937* rng) {
  // A shared encoder's critics are heads on its 512 features.
  const int input = config.network == "drq" ? 512 : spec.observation_size;
  return nn::BuildActionValueNet(Td3CriticArchitecture(config, spec), input, spec.action_dim, rng);
}

std::mt19937 InitRng(uint64_t seed) { return std::mt19937(static_cast<uint32_t>(seed)); }

}  // namespace

Td3::Td3(const envs::EnvSpec& spec, Td3Config config)
    : spec_(spec), config_(std::move(config)), action_dim_(spec.action_dim) {
  std::mt19937 rng = InitRng(config_.seed);
  shared_encoder_ = config_.network == "drq";
  if (shared_encoder_) {
    // The policy that is broadcast: encoder then actor head, in one Sequential whose flat
    // parameters are the encoder's followed by the head's (neither has buffers).
    policy_ = BuildActor(config_, spec_, &rng);
    encoder_ = nn::BuildFromArchitecture(nn::CarEncoderArchitecture(), &rng);
    actor_ = nn::BuildFromArchitecture(
        nn::DrqActorHeadArchitecture(config_.hidden.front(), spec_.action_low, spec_.action_high),
        &rng);
    if (encoder_.NumBuffers() != 0 || actor_.NumBuffers() != 0 ||
        policy_.FlatSize() != encoder_.FlatSize() + actor_.FlatSize()) {
      throw std::logic_error("td3 drq: the policy is not the encoder followed by the head");
    }
  } else {
    actor_ = BuildActor(config_, spec_, &rng);
  }
  q1_ = BuildCritic(config_, spec_, &rng);
  q2_ = BuildCritic(config_, spec_, &rng);
  encoder_.set_precision(config_.encoder_precision.empty()
                             ? config_.precision
                             : nn::ParsePrecision(config_.encoder_precision));
  actor_.set_precision(config_.precision);
  for (nn::ActionValueNet* net : {&q1_, &q2_}) net->set_precision(config_.precision);
  actor_target_ = actor_;
  q1_target_ = q1_;
  q2_target_ = q2_;
  actor_target_.set_training(false);
  q1_target_.set_training(false);
  q2_target_.set_training(false);
  actor_params_ = actor_.Params();
  critic_params_ = shared_encoder_ ? encoder_.Params() : std::vector<nn::Param>{};
  const std::vector<nn::Param> q1_params = q1_.Params();
  critic_params_.insert(critic_params_.end(), q1_params.begin(), q1_params.end());
  const std::vector<nn::Param> q2_params = q2_.Params();
  critic_params_.insert(critic_params_.end(), q2_params.begin(), q2_params.end());
  actor_optimizer_ = std::make_unique<nn::Adam>(actor_params_, config_.actor_learning_rate, 0.9f,
                                                0.999f, config_.adam_eps);
  critic_optimizer_ = std::make_unique<nn::Adam>(critic_params_, config_.critic_learning_rate, 0.9f,
                                                 0.999f, config_.adam_eps);
  noise_rng_.seed(config_.seed + 1);
}

nn::Sequential& Td3::policy() {
  if (!shared_encoder_) return actor_;
  encoder_.GetFlat(&flat_);
  actor_.GetFlat(&head_flat_);
  flat_.insert(flat_.end(), head_flat_.begin(), head_flat_.end());
  policy_.SetFlat(flat_.data(), flat_.size());
  return policy_;
}

std::string Td3::Describe() const {
  std::string d = "TD3, " + config_.network;
  if (config_.network == "mlp") d += ' ' + Widths(config_.hidden);
  if (shared_encoder_) {
    d += " (one encoder trained by the critics, heads of " +
         std::to_string(config_.hidden.front()) + ")";
  }
  d += ", actor ";
  d += actor_.Architecture();
  return d;
}

void Td3::TargetActions(const nn::Matrix& next_obs) {
  next_action_ = actor_target_.Forward(next_obs);
  for (Eigen::Index i = 0; i < next_action_.cols(); ++i) {
    for (int d = 0; d < action_dim_; ++d) {
      const auto k = static_cast<size_t>(d);
      const float half = (spec_.action_high[k] - spec_.action_low[k]) / 2;
      const float clip = config_.target_noise_clip * half;
      float noise = 0;
      if (config_.target_noise > 0) {
        noise = std::clamp(config_.target_noise * half * normal_(noise_rng_), -clip, clip);
      }
      next_action_(d, i) =
          std::clamp(next_action_(d, i) + noise, spec_.action_low[k], spec_.action_high[k]);
    }
  }
}

void Td3::SetLearningRateScale(float scale) {
  actor_optimizer_->set_learning_rate(config_.actor_learning_rate * scale);
  critic_optimizer_->set_learning_rate(config_.critic_learning_rate * scale);
}

UpdateResult Td3::Update(const Batch& b) {
  const int n = b.count;
  if (n < 1) throw std::invalid_argument("empty batch");
  if (b.obs == nullptr || b.next_obs == nullptr || b.obs->rows() != spec_.observation_size ||
      b.next_obs->rows() != spec_.observation_size || b.obs->cols() != n ||
      b.next_obs->cols() != n) {
    throw std::invalid_argument("batch observation size mismatch");
  }
  if (b.action_width != action_dim_ ||
      static_cast<int64_t>(b.action.size()) != int64_t{n} * action_dim_) {
    throw std::invalid_argument("batch action width " + std::to_string(b.action_width) +
                                ", TD3 has " + std::to_string(action_dim_));
  }
  // With a shared encoder the networks below see its features: s' first (a constant), then s,
  // whose activations the critics' backward pass goes through.
  const nn::Matrix* obs_in = b.obs;
  const nn::Matrix* next_in = b.next_obs;
  if (shared_encoder_) {
    encoder_.ZeroGrad();
    next_features_ = encoder_.Forward(*b.next_obs);
    features_ = encoder_.Forward(*b.obs);
    obs_in = &features_;
    next_in = &next_features_;
  }
  const nn::Matrix& obs = *obs_in;
  const nn::Matrix& next_obs = *next_in;
  action_ = Eigen::Map<const nn::Matrix>(b.action.data(), action_dim_, n);
  if (!action_.allFinite()) throw std::invalid_argument("action not finite");

  // Targets: clipped double-Q at the smoothed target action. The twin critics are independent
  // networks on the same inputs, so their passes run as two tasks of the nn thread pool (on one
  // thread, one after the other): the heads' products are too small to split themselves, and
  // each computed whole in a task gives the same result as on the calling thread.
  TargetActions(next_obs);
  const nn::Matrix* target_q[2] = {nullptr, nullptr};
  nn::internal::ParallelFor(2, [&](int k) {
    target_q[k] = &(k == 0 ? q1_target_ : q2_target_).Forward(next_obs, next_action_);
  });
  y_ = target_q[0]->row(0).transpose();
  for (int i = 0; i < n; ++i) {
    const auto k = static_cast<size_t>(i);
    y_[i] = b.reward[k] + b.discount[k] * std::min(y_[i], (*target_q[1])(0, i));
  }

  const nn::Vector* w = nullptr;
  if (!b.weight.empty()) {
    weights_ = Eigen::Map<const nn::Vector>(b.weight.data(), n);
    w = &weights_;
  }
  // Critics: each regressed on y, side by side as above; with a shared encoder each gives
  // d(loss)/d(features) too, and the encoder learns from their sum.
  UpdateResult result;
  float losses[2] = {0.0f, 0.0f};
  nn::internal::ParallelFor(2, [&](int k) {
    nn::ActionValueNet& q = k == 0 ? q1_ : q2_;
    q.ZeroGrad();
    q_pred_[k] = q.Forward(obs, action_).row(0).transpose();
    losses[k] = nn::MseLoss(q_pred_[k], y_, &loss_grad_[k], w);
    grad_q_[k] = loss_grad_[k].transpose();
    if (shared_encoder_) {
      q.Backward(grad_q_[k]);
    } else {
      q.BackwardParams(grad_q_[k]);
    }
  });
  result.loss = losses[0];
  result.loss += losses[1];
  if (shared_encoder_) {
    grad_features_ = q1_.grad_obs();
    grad_features_ += q2_.grad_obs();
    encoder_.BackwardParams(grad_features_);
  }
  if (config_.max_grad_norm > 0) {
    result.grad_norm = nn::ClipGradNorm(critic_params_, config_.max_grad_norm);
  }
  critic_optimizer_->Step();
  // The first critic's prediction (index 0: q1) gives the mean Q and the TD errors, as in TD3.
  result.mean_q = q_pred_[0].mean();
  td_abs_.resize(static_cast<size_t>(n));
  for (int i = 0; i < n; ++i) td_abs_[static_cast<size_t>(i)] = std::abs(y_[i] - q_pred_[0][i]);
  ++updates_;

  if (updates_ % config_.policy_delay == 0) {
    // Actor: ascend Q1(s, mu(s)); the critic's parameter gradients of this pass are discarded.
    actor_.ZeroGrad();
    const nn::Matrix& mu = actor_.Forward(obs);
    q1_.Forward(obs, mu);
    grad_q_[0].setConstant(1, n, -1.0f / static_cast<float>(n));
    q1_.BackwardParams(grad_q_[0]);  // computes dQ/da too
    grad_actor_ = q1_.grad_action();
    actor_.BackwardParams(grad_actor_);
    if (config_.max_grad_norm > 0) nn::ClipGradNorm(actor_params_, config_.max_grad_norm);
    actor_optimizer_->Step();
    q1_.ZeroGrad();
    ++actor_updates_;
    // Targets follow slowly.
    actor_target_.SoftUpdateFrom(actor_, config_.tau);
    q1_target_.SoftUpdateFrom(q1_, config_.tau);
    q2_target_.SoftUpdateFrom(q2_, config_.tau);
  }
  return result;
}

void Td3::SaveState(StateFile* state) const {
  PutNet(state, "td3.actor", actor_);
  PutNet(state, "td3.actor_target", actor_target_);
  PutNet(state, "td3.q1", q1_);
  PutNet(state, "td3.q2", q2_);
  PutNet(state, "td3.q1_target", q1_target_);
  PutNet(state, "td3.q2_target", q2_target_);
  if (shared_encoder_) PutNet(state, "td3.encoder", encoder_);
  PutOptimizer(state, "td3.actor_optimizer", *actor_optimizer_);
  PutOptimizer(state, "td3.critic_optimizer", *critic_optimizer_);
  state->PutInts("td3.updates", std::vector<int64_t>{updates_, actor_updates_});
  PutRng(state, "td3.noise_rng", noise_rng_);
  PutRng(state, "td3.normal", normal_);
}

void Td3::LoadState(const StateFile& state) {
  GetNet(state, "td3.actor", &actor_);
  GetNet(state, "td3.actor_target", &actor_target_);
  GetNet(state, "td3.q1", &q1_);
  GetNet(state, "td3.q2", &q2_);
  GetNet(state, "td3.q1_target", &q1_target_);
  GetNet(state, "td3.q2_target", &q2_target_);
  if (shared_encoder_) GetNet(state, "td3.encoder", &encoder_);
  GetOptimizer(state, "td3.actor_optimizer", actor_optimizer_.get());
  GetOptimizer(state, "td3.critic_optimizer", critic_optimizer_.get());
  const std::span<const int64_t> counts = state.Ints("td3.updates");
  if (counts.size() != 2) throw std::runtime_error("state section 'td3.updates' is malformed");
  updates_ = counts[0];
  actor_updates_ = counts[1];
  GetRng(state, "td3.noise_rng", &noise_rng_);
  GetRng(state, "td3.normal", &normal_);
}

}  // namespace rl::learner
