// The dueling head of Wang et al. 2016, "Dueling Network Architectures for Deep Reinforcement
// Learning".
#pragma once

#include <memory>
#include <random>
#include <string>
#include <vector>

#include "nn/layer.h"
#include "nn/linear.h"
#include "nn/tensor.h"

namespace rl::nn {

/// Two streams on the same in_features input, each a hidden ReLU layer:
///   value:     V = linear(hidden, 1)(relu(linear(in, hidden)(x)))
///   advantage: A = linear(hidden, num_actions)(relu(linear(in, hidden)(x)))
/// combined as Q = V + A - mean(A) (the mean over the actions of each sample).
///
/// Params(), in this order, named like the state_dict of a PyTorch module holding two
/// nn.Sequential streams: "value.0.weight", "value.0.bias", "value.2.weight", "value.2.bias",
/// "advantage.0.weight", "advantage.0.bias", "advantage.2.weight", "advantage.2.bias"; shapes as in
/// Linear. Initialised as four Linear layers drawn in that order.
class Dueling : public Layer {
 public:
  /// Throws std::invalid_argument unless all sizes are positive.
  Dueling(int in_features, int hidden, int num_actions, std::mt19937* rng);

  const Matrix& Forward(const Matrix& x) override;
  const Matrix& Backward(const Matrix& grad_out) override;
  void BackwardParams(const Matrix& grad_out) override;
  std::vector<Param> Params() override;
  std::string Describe() const override;
  std::unique_ptr<Layer> Clone() const override;
  int input_size() const override { return value_hidden_.input_size(); }
  int output_size() const override { return advantage_out_.output_size(); }
  bool FuseInputReluGrad() override;
  void set_precision(Precision precision) override;

  Linear& value_hidden() { return value_hidden_; }
  Linear& value_out() { return value_out_; }
  Linear& advantage_hidden() { return advantage_hidden_; }
  Linear& advantage_out() { return advantage_out_; }

 private:
  Dueling(const Linear& value_hidden, const Linear& value_out, const Linear& advantage_hidden,
          const Linear& advantage_out);
  // Fuses the hidden ReLUs into the Linear layers around them.
  void FuseHiddenRelus();
  // Back-propagates grad_out through the combination and both output layers; leaves the
  // gradients at the hidden layers' outputs in their Backward() results.
  void BackwardHead(const Matrix& grad_out);

  Linear value_hidden_;
  Linear value_out_;
  Linear advantage_hidden_;
  Linear advantage_out_;
  Matrix output_;      // num_actions x batch.
  Matrix grad_value_;  // 1 x batch.
  Matrix grad_advantage_;
  Matrix grad_input_;
  const Matrix* grad_value_hidden_ = nullptr;
  const Matrix* grad_advantage_hidden_ = nullptr;
  Precision precision_ = Precision::kFp32;
};

}  // namespace rl::nn
