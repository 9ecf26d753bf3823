// Batch normalisation over the channels of images (Ioffe & Szegedy 2015), as PyTorch's
// nn.BatchNorm2d.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "nn/layer.h"
#include "nn/tensor.h"

namespace rl::nn {

/// y = (x - mean_c) / sqrt(var_c + eps) * weight_c + bias_c for every pixel of channel c of
/// channels x h x w images (channel-major columns, see ImageShape).
///
/// Training mode (the default) normalises with the statistics of the batch, over the batch and
/// the pixels (N = batch * h * w values per channel, biased variance), and updates the running
/// statistics as PyTorch does with momentum 0.1:
///   running_mean = 0.9 running_mean + 0.1 mean,  running_var = 0.9 running_var + 0.1 var N/(N-1)
/// Evaluation mode normalises with the running statistics and leaves them alone. The running
/// statistics start at 0 and 1; weight and bias (the trainable affine part) at 1 and 0.
///
/// Params(): "weight", "bias" (channels x 1). Buffers(): "running_mean", "running_var"
/// (channels x 1). Forward() keeps a pointer to its input (see Layer).
class BatchNorm2d : public Layer {
 public:
  static constexpr float kMomentum = 0.1f;
  static constexpr float kEps = 1e-5f;

  /// Throws std::invalid_argument unless all sizes are positive.
  BatchNorm2d(int channels, int height, int width);

  /// Throws std::invalid_argument in training mode if a channel has a single value (batch 1 of
  /// 1 x 1 images), whose variance is undefined, as PyTorch does.
  const Matrix& Forward(const Matrix& x) override;
  const Matrix& Backward(const Matrix& grad_out) override;
  void BackwardParams(const Matrix& grad_out) override;
  std::vector<Param> Params() override;
  std::vector<Buffer> Buffers() override;
  void set_training(bool training) override { training_ = training; }
  bool training() const { return training_; }
  std::string Describe() const override;
  std::unique_ptr<Layer> Clone() const override;
  int input_size() const override { return shape_.size(); }
  int output_size() const override { return shape_.size(); }
  ImageShape input_shape() const override { return shape_; }
  ImageShape output_shape() const override { return shape_; }
  bool FuseOutputRelu() override {
    fused_output_relu_ = true;
    return true;
  }

  Matrix& weight() { return weight_; }
  Matrix& bias() { return bias_; }
  Matrix& running_mean() { return running_mean_; }
  Matrix& running_var() { return running_var_; }
  const Matrix& running_mean() const { return running_mean_; }
  const Matrix& running_var() const { return running_var_; }
  const Matrix& weight_grad() const { return weight_grad_; }
  const Matrix& bias_grad() const { return bias_grad_; }

 private:
  void BackwardImpl(const Matrix& grad_out, bool input_grad);

  ImageShape shape_;
  bool training_ = true;
  bool fused_output_relu_ = false;
  Matrix weight_;  // gamma, channels x 1.
  Matrix bias_;    // beta.
  Matrix weight_grad_;
  Matrix bias_grad_;
  Matrix running_mean_;
  Matrix running_var_;
  // Of the last Forward(): the statistics it normalised with, as mean and 1 / sqrt(var + eps), and
  // whether they were the batch's.
  Vector mean_;
  Vector inv_std_;
  bool batch_stats_ = true;
  Vector sum_dy_;  // Per channel: sum of dy, and of dy * xhat.
  Vector sum_dy_xhat_;
  const Matrix* input_ = nullptr;
  Matrix output_;
  Matrix grad_input_;
};

}  // namespace rl::nn
