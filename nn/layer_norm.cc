#include "nn/layer_norm.h"

#include <cmath>
#include <stdexcept>
#include <string>

#include "common/check.h"

namespace rl::nn {

LayerNorm::LayerNorm(int features) : features_(features) {
  if (features <= 0) throw std::invalid_argument(Describe() + ": features must be positive");
  weight_.setOnes(features, 1);
  bias_.setZero(features, 1);
  weight_grad_.setZero(features, 1);
  bias_grad_.setZero(features, 1);
}

const Matrix& LayerNorm::Forward(const Matrix& x) {
  RL_CHECK(x.rows() == features_) << Describe() << " got an input with " << x.rows() << " rows";
  const auto batch = x.cols();
  xhat_.resize(features_, batch);
  inv_std_.resize(batch);
  output_.resize(features_, batch);
  const auto n = static_cast<double>(features_);
  for (Eigen::Index j = 0; j < batch; ++j) {
    // Two passes in double, as BatchNorm2d.
    const double mean = static_cast<double>(x.col(j).sum()) / n;
    const auto centred = x.col(j).array() - static_cast<float>(mean);
    const double var = static_cast<double>(centred.square().sum()) / n;
    inv_std_[j] = static_cast<float>(1.0 / std::sqrt(var + static_cast<double>(kEps)));
    xhat_.col(j).array() = centred * inv_std_[j];
    output_.col(j).array() = xhat_.col(j).array() * weight_.col(0).array() + bias_.col(0).array();
  }
  return output_;
}

const Matrix& LayerNorm::Backward(const Matrix& grad_out) {
  RL_CHECK(grad_out.rows() == features_ && grad_out.cols() == xhat_.cols())
      << Describe() << " got an output gradient of " << grad_out.rows() << "x" << grad_out.cols()
      << " for a batch of " << xhat_.cols();
  const auto batch = grad_out.cols();
  const auto n = static_cast<float>(features_);
  grad_input_.resize(features_, batch);
  for (Eigen::Index j = 0; j < batch; ++j) {
    const auto dy = grad_out.col(j).array();
    const auto xhat = xhat_.col(j).array();
    weight_grad_.col(0).array() += dy * xhat;
    bias_grad_.col(0).array() += dy;
    // With g = dy * weight: dx = inv_std (g - mean(g) - xhat mean(g xhat)).
    auto g = grad_input_.col(j).array();
    g = dy * weight_.col(0).array();
    const float mean_g = g.sum() / n;
    const float mean_gx = (g * xhat).sum() / n;
    g = inv_std_[j] * (g - mean_g - xhat * mean_gx);
  }
  return grad_input_;
}

std::vector<Param> LayerNorm::Params() {
  return {{"weight", &weight_, &weight_grad_}, {"bias", &bias_, &bias_grad_}};
}

std::string LayerNorm::Describe() const { return "layernorm(" + std::to_string(features_) + ")"; }

std::unique_ptr<Layer> LayerNorm::Clone() const {
  auto copy = std::make_unique<LayerNorm>(features_);
  copy->weight_ = weight_;
  copy->bias_ = bias_;
  return copy;
}

}  // namespace rl::nn
