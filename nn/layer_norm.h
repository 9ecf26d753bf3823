// Layer normalisation (Ba, Kiros & Hinton 2016), as PyTorch's nn.LayerNorm over the last
// dimension.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "nn/layer.h"
#include "nn/tensor.h"

namespace rl::nn {

/// Normalises each sample (column) over its `features` rows, then applies a per-feature affine
/// map: y = (x - mean) / sqrt(var + eps) * weight + bias, with the biased variance of the column
/// and eps = 1e-5. The same in training and evaluation mode. weight starts at 1, bias at 0
/// (features x 1 each). On images it normalises over all of C x H x W, as
/// nn.LayerNorm([C, H, W]).
class LayerNorm : public Layer {
 public:
  static constexpr float kEps = 1e-5f;

  /// Throws std::invalid_argument unless features > 0.
  explicit LayerNorm(int features);

  const Matrix& Forward(const Matrix& x) override;
  const Matrix& Backward(const Matrix& grad_out) override;
  std::vector<Param> Params() override;
  std::string Describe() const override;
  std::unique_ptr<Layer> Clone() const override;
  int input_size() const override { return features_; }
  int output_size() const override { return features_; }

  Matrix& weight() { return weight_; }
  Matrix& bias() { return bias_; }
  const Matrix& weight_grad() const { return weight_grad_; }
  const Matrix& bias_grad() const { return bias_grad_; }

 private:
  int features_;
  Matrix weight_;  // features x 1.
  Matrix bias_;
  Matrix weight_grad_;
  Matrix bias_grad_;
  Matrix xhat_;     // Normalised input of the last Forward(), features x batch.
  Vector inv_std_;  // Per column of the last Forward().
  Matrix output_;
  Matrix grad_input_;
};

}  // namespace rl::nn
