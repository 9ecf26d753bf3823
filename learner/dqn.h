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

#include "nn/optimizers.h"
#include "nn/sequential.h"

namespace rl::learner {

struct DqnConfig {
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
  // Pixel batches: shift each observation and each next observation by its own random offset
  // of up to this many pixels in y and x, edges repeated (DrQ's random shift, Kostrikov et al.
  // 2020; they use 4 on 84 x 84 frames). 0: no augmentation.
  int augment_shift = 0;
  uint64_t seed = 0;  // initialisation seed (and the seed of the shifts)

  // Throws std::invalid_argument naming the bad field.
  void Validate() const;
};

// The architecture string DqnConfig describes, for observations of obs_size values. Throws
// std::invalid_argument when the network cannot take such observations.
std::string QNetworkArchitecture(const DqnConfig& config, int obs_size, int num_actions);

// A batch of transitions laid out as in the messages: transition i's observation is
// obs[i*obs_size .. (i+1)*obs_size). Pixel batches give bytes instead (obs_pixels and
// next_obs_pixels, divided by 255 on the way into the network) and leave obs and next_obs null;
// their frames are frame_height x frame_width (needed for augment_shift).
struct BatchView {
  int obs_size = 0;
  int count = 0;
  int frame_height = 0;
  int frame_width = 0;
  const float* obs = nullptr;
  const float* next_obs = nullptr;
  const uint8_t* obs_pixels = nullptr;
  const uint8_t* next_obs_pixels = nullptr;
  const int32_t* action = nullptr;
  const float* reward = nullptr;
  const float* discount = nullptr;
  const float* weight = nullptr;  // importance weights, or nullptr for all ones
};

struct UpdateResult {
  float loss = 0;    // mean (weighted) loss of the batch
  float mean_q = 0;  // mean Q of the chosen actions
  float grad_norm = 0;
};

class Dqn {
 public:
  Dqn(int obs_size, int num_actions, DqnConfig config);
  Dqn(const Dqn&) = delete;
  Dqn& operator=(const Dqn&) = delete;

  // One gradient step on the batch. Throws std::invalid_argument on a batch whose observation
  // size or actions do not fit the network.
  UpdateResult Update(const BatchView& batch);

  // |TD error| of each transition of the last Update (for prioritized replay).
  const std::vector<float>& last_td_errors() const { return td_abs_; }

  nn::Sequential& online() { return online_; }
  const nn::Sequential& target() const { return target_; }
  int64_t updates() const { return updates_; }
  const DqnConfig& config() const { return config_; }

 private:
  // Pixels to network inputs, each observation shifted at random by up to augment_shift.
  void ShiftedPixels(const uint8_t* pixels, int planes, int height, int width, int n,
                     nn::Matrix* out);

  DqnConfig config_;
  int obs_size_;
  int num_actions_;
  nn::Sequential online_;
  nn::Sequential target_;
  std::unique_ptr<nn::Optimizer> optimizer_;
  std::vector<nn::Param> params_;
  int64_t updates_ = 0;
  std::mt19937_64 shift_rng_;  // augment_shift's offsets

  // Buffers reused by every update.
  nn::Matrix obs_, next_obs_, grad_q_;
  nn::Vector pred_, target_values_, loss_grad_, weights_;
  std::vector<int> next_actions_;
  std::vector<int> shift_y_, shift_x_;
  std::vector<float> td_abs_;
};

}  // namespace rl::learner
