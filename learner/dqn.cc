#include "learner/dqn.h"

#include <cmath>
#include <stdexcept>
#include <string>

#include "common/options.h"
#include "learner/algorithm_state.h"
#include "nn/losses.h"
#include "nn/pixels.h"
#include "nn/presets.h"

namespace rl::learner {

void DqnConfig::Validate() const {
  if (network.empty()) throw std::invalid_argument("network must not be empty");
  if (hidden.empty()) throw std::invalid_argument("hidden: at least one hidden layer");
  for (int h : hidden) {
    if (h < 1) throw std::invalid_argument("hidden: widths must be >= 1");
  }
  if (optimizer != "adam" && optimizer != "rmsprop") {
    throw std::invalid_argument("optimizer must be adam or rmsprop, not '" + optimizer + "'");
  }
  if (loss != "huber" && loss != "mse") {
    throw std::invalid_argument("loss must be huber or mse, not '" + loss + "'");
  }
  if (!(learning_rate > 0)) throw std::invalid_argument("learning-rate must be > 0");
  if (target_update_period < 1) throw std::invalid_argument("target-update-period must be >= 1");
  if (!(tau > 0 && tau <= 1)) throw std::invalid_argument("tau must be in (0, 1]");
  if (!(max_grad_norm >= 0)) throw std::invalid_argument("max-grad-norm must be >= 0");
}

void DqnConfig::AddOptions(po::options_description* desc) {
  desc->add_options()  //
      ("dueling", po::value(&dueling)->default_value(dueling),
       "dueling value and advantage streams (1/0; mlp, nature, grasp, grasp48)")               //
      ("optimizer", po::value(&optimizer)->default_value(optimizer), "adam or rmsprop")        //
      ("learning-rate", po::value(&learning_rate)->default_value(learning_rate), "step size")  //
      ("rmsprop-alpha", po::value(&rmsprop_alpha)->default_value(rmsprop_alpha),
       "RMSProp smoothing constant (DeepMind: 0.95)")  //
      ("rmsprop-eps", po::value(&rmsprop_eps)->default_value(rmsprop_eps),
       "RMSProp epsilon (DeepMind: 0.01)")  //
      ("rmsprop-centered", po::value(&rmsprop_centered)->default_value(rmsprop_centered),
       "centered RMSProp, as DeepMind's (1/0)")                        //
      ("loss", po::value(&loss)->default_value(loss), "huber or mse")  //
      ("double-dqn", po::value(&double_dqn)->default_value(double_dqn),
       "Double DQN targets (1/0)")  //
      ("target-update-period",
       po::value(&target_update_period)->default_value(target_update_period),
       "updates between target network refreshes");
}

std::unique_ptr<Algorithm> DqnConfig::Make(const envs::EnvSpec& spec) const {
  if (spec.continuous()) {
    throw std::invalid_argument(spec.id +
                                " has continuous actions; DQN needs discrete ones (use "
                                "algorithm = td3)");
  }
  return std::make_unique<Dqn>(spec.observation_size, spec.num_actions, *this);
}

std::string QNetworkArchitecture(const DqnConfig& config, int obs_size, int num_actions) {
  const auto fail = [&](const std::string& why) {
    return std::invalid_argument("network '" + config.network + "': " + why);
  };
  if (obs_size < 1 || num_actions < 1) throw fail("needs observations and actions");
  if (config.network == "mlp") {
    std::string arch;
    int in = obs_size;
    const size_t n = config.hidden.size();
    // With dueling, the last hidden width is the streams' own hidden layer.
    for (size_t i = 0; i + (config.dueling ? 1 : 0) < n; ++i) {
      arch += "linear(" + std::to_string(in) + "," + std::to_string(config.hidden[i]) + "),relu,";
      in = config.hidden[i];
    }
    if (config.dueling) {
      return arch + "dueling(" + std::to_string(in) + "," + std::to_string(config.hidden.back()) +
             "," + std::to_string(num_actions) + ")";
    }
    return arch + "linear(" + std::to_string(in) + "," + std::to_string(num_actions) + ")";
  }
  if (config.network == "nature") {
    if (obs_size != 4 * 84 * 84) throw fail("takes 4 x 84 x 84 observations");
    return nn::NatureCnnArchitecture(num_actions, config.dueling);
  }
  if (config.network == "grasp") {
    if (obs_size % (40 * 40) != 0) throw fail("takes stacks of 40 x 40 frames");
    return nn::GraspCnnArchitecture(num_actions, obs_size / (40 * 40), config.dueling);
  }
  if (config.network == "grasp48") {
    if (obs_size % (48 * 48) != 0) throw fail("takes stacks of 48 x 48 frames");
    return nn::Grasp48CnnArchitecture(num_actions, obs_size / (48 * 48), config.dueling);
  }
  if (config.network.find('(') == std::string::npos) {
    throw fail("expected mlp, nature, grasp, grasp48 or an architecture string");
  }
  if (config.dueling) {
    throw fail("dueling applies to mlp, nature, grasp and grasp48; write dueling(...)");
  }
  return config.network;
}

Dqn::Dqn(int obs_size, int num_actions, DqnConfig config)
    : config_(std::move(config)), obs_size_(obs_size), num_actions_(num_actions) {
  config_.Validate();
  std::mt19937 rng(static_cast<std::mt19937::result_type>(config_.seed));
  online_ = nn::BuildFromArchitecture(QNetworkArchitecture(config_, obs_size, num_actions), &rng);
  if (online_.InputSize() != obs_size || online_.OutputSize() != num_actions) {
    throw std::invalid_argument("network '" + config_.network + "' takes " +
                                std::to_string(online_.InputSize()) + " inputs and gives " +
                                std::to_string(online_.OutputSize()) + " outputs; the env has " +
                                std::to_string(obs_size) + " and " + std::to_string(num_actions));
  }
  online_.set_precision(config_.precision);
  target_ = online_;
  target_.set_training(false);  // the target network uses running statistics (BatchNorm)
  params_ = online_.Params();
  if (config_.optimizer == "adam") {
    optimizer_ =
        std::make_unique<nn::Adam>(params_, config_.learning_rate, 0.9f, 0.999f, config_.adam_eps);
  } else {
    optimizer_ =
        std::make_unique<nn::RmsProp>(params_, config_.learning_rate, config_.rmsprop_alpha,
                                      config_.rmsprop_eps, config_.rmsprop_centered);
  }
}

std::string Dqn::Describe() const {
  return std::string(config_.double_dqn ? "Double DQN" : "DQN") + ", " + online_.Architecture();
}

void Dqn::SetLearningRateScale(float scale) {
  optimizer_->set_learning_rate(config_.learning_rate * scale);
}

UpdateResult Dqn::Update(const Batch& b) {
  if (b.obs == nullptr || b.next_obs == nullptr || b.obs->rows() != obs_size_ ||
      b.next_obs->rows() != obs_size_ || b.obs->cols() != b.count ||
      b.next_obs->cols() != b.count) {
    throw std::invalid_argument("batch observation size mismatch");
  }
  if (b.count < 1) throw std::invalid_argument("empty batch");
  if (b.action_width != 1 || static_cast<int>(b.action.size()) != b.count) {
    throw std::invalid_argument("DQN takes one action value (the index) per transition");
  }
  const int n = b.count;
  // Actions are indices; check them all before anything changes.
  actions_.resize(static_cast<size_t>(n));
  for (int i = 0; i < n; ++i) {
    const float a = b.action[static_cast<size_t>(i)];
    if (!(a >= 0 && a < static_cast<float>(num_actions_)) ||
        a != static_cast<float>(static_cast<int>(a))) {
      throw std::invalid_argument("action outside the network's");
    }
    actions_[static_cast<size_t>(i)] = static_cast<int>(a);
  }
  const nn::Matrix& obs = *b.obs;
  const nn::Matrix& next_obs = *b.next_obs;

  // Targets y = r + discount * Q_target(s', a*), a* = argmax of the online (Double DQN) or
  // target network. The online network's forward on s' comes first, because the forward on s
  // below must stay cached for the backward pass.
  next_actions_.resize(static_cast<size_t>(n));
  if (config_.double_dqn) {
    const nn::Matrix& q_online_next = online_.Forward(next_obs);
    for (int i = 0; i < n; ++i)
      q_online_next.col(i).maxCoeff(&next_actions_[static_cast<size_t>(i)]);
  }
  const nn::Matrix& q_next = target_.Forward(next_obs);
  target_values_.resize(n);
  for (int i = 0; i < n; ++i) {
    int a = 0;
    if (config_.double_dqn) {
      a = next_actions_[static_cast<size_t>(i)];
    } else {
      q_next.col(i).maxCoeff(&a);
    }
    const auto k = static_cast<size_t>(i);
    target_values_[i] = b.reward[k] + b.discount[k] * q_next(a, i);
  }

  // Q(s, a) of the taken actions.
  const nn::Matrix& q = online_.Forward(obs);
  pred_.resize(n);
  for (int i = 0; i < n; ++i) {
    pred_[i] = q(actions_[static_cast<size_t>(i)], i);
  }
  const nn::Vector* w = nullptr;
  if (!b.weight.empty()) {
    weights_ = Eigen::Map<const nn::Vector>(b.weight.data(), n);
    w = &weights_;
  }
  UpdateResult result;
  result.loss = config_.loss == "huber" ? nn::HuberLoss(pred_, target_values_, &loss_grad_, 1.0f, w)
                                        : nn::MseLoss(pred_, target_values_, &loss_grad_, w);
  result.mean_q = pred_.mean();
  td_abs_.resize(static_cast<size_t>(n));
  for (int i = 0; i < n; ++i)
    td_abs_[static_cast<size_t>(i)] = std::abs(target_values_[i] - pred_[i]);

  // Gradient flows only into the chosen actions' outputs.
  grad_q_.setZero(num_actions_, n);
  for (int i = 0; i < n; ++i) grad_q_(actions_[static_cast<size_t>(i)], i) = loss_grad_[i];
  online_.ZeroGrad();
  online_.BackwardParams(grad_q_);  // parameter gradients only: no input gradient needed
  if (config_.max_grad_norm > 0) {
    result.grad_norm = nn::ClipGradNorm(params_, config_.max_grad_norm);
  }
  optimizer_->Step();
  ++updates_;
  if (updates_ % config_.target_update_period == 0) {
    if (config_.tau >= 1.0f) {
      target_.CopyParamsFrom(online_);
    } else {
      target_.SoftUpdateFrom(online_, config_.tau);
    }
  }
  return result;
}

void Dqn::SaveState(StateFile* state) const {
  PutNet(state, "dqn.online", online_);
  PutNet(state, "dqn.target", target_);
  PutOptimizer(state, "dqn.optimizer", *optimizer_);
  state->PutInt("dqn.updates", updates_);
}

void Dqn::LoadState(const StateFile& state) {
  GetNet(state, "dqn.online", &online_);
  GetNet(state, "dqn.target", &target_);
  GetOptimizer(state, "dqn.optimizer", optimizer_.get());
  updates_ = state.Int("dqn.updates");
}

}  // namespace rl::learner
