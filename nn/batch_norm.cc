#include "nn/batch_norm.h"

#include <cmath>
#include <stdexcept>
#include <string>

#include "common/check.h"

namespace rl::nn {

BatchNorm2d::BatchNorm2d(int channels, int height, int width) : shape_{channels, height, width} {
  if (channels <= 0 || height <= 0 || width <= 0) {
    throw std::invalid_argument(Describe() + ": sizes must be positive");
  }
  weight_.setOnes(channels, 1);
  bias_.setZero(channels, 1);
  weight_grad_.setZero(channels, 1);
  bias_grad_.setZero(channels, 1);
  running_mean_.setZero(channels, 1);
  running_var_.setOnes(channels, 1);
  mean_.setZero(channels);
  inv_std_.setZero(channels);
  sum_dy_.setZero(channels);
  sum_dy_xhat_.setZero(channels);
}

const Matrix& BatchNorm2d::Forward(const Matrix& x) {
  RL_CHECK(x.rows() == shape_.size()) << Describe() << " got an input with " << x.rows() << " rows";
  input_ = &x;
  const auto batch = static_cast<int>(x.cols());
  const int channels = shape_.channels;
  const int pixels = shape_.height * shape_.width;
  const int64_t n = static_cast<int64_t>(batch) * pixels;
  batch_stats_ = training_;

  if (training_) {
    if (n <= 1) {
      throw std::invalid_argument(Describe() + ": training mode needs more than one value per " +
                                  "channel, got a batch of " + std::to_string(batch));
    }
    // Two passes per channel (mean, then the squared deviations) in double: E[x^2] - E[x]^2
    // cancels badly when the mean is large.
    for (int c = 0; c < channels; ++c) {
      double sum = 0.0;
      for (int b = 0; b < batch; ++b) {
        sum +=
            static_cast<double>(x.col(b).segment(static_cast<int64_t>(c) * pixels, pixels).sum());
      }
      const double mean = sum / static_cast<double>(n);
      double sq = 0.0;
      for (int b = 0; b < batch; ++b) {
        const auto seg = x.col(b).segment(static_cast<int64_t>(c) * pixels, pixels).array();
        sq += static_cast<double>((seg - static_cast<float>(mean)).square().sum());
      }
      const double var = sq / static_cast<double>(n);
      mean_[c] = static_cast<float>(mean);
      inv_std_[c] = static_cast<float>(1.0 / std::sqrt(var + static_cast<double>(kEps)));
      const double unbiased = var * static_cast<double>(n) / static_cast<double>(n - 1);
      running_mean_(c, 0) =
          (1.0f - kMomentum) * running_mean_(c, 0) + kMomentum * static_cast<float>(mean);
      running_var_(c, 0) =
          (1.0f - kMomentum) * running_var_(c, 0) + kMomentum * static_cast<float>(unbiased);
    }
  } else {
    mean_ = running_mean_.col(0);
    inv_std_ = (running_var_.col(0).array() + kEps).rsqrt();
  }

  // y = x * scale + shift per channel.
  output_.resize(x.rows(), batch);
  for (int b = 0; b < batch; ++b) {
    for (int c = 0; c < channels; ++c) {
      const float scale = weight_(c, 0) * inv_std_[c];
      const float shift = bias_(c, 0) - mean_[c] * scale;
      const int64_t at = static_cast<int64_t>(c) * pixels;
      auto y = output_.col(b).segment(at, pixels).array();
      y = x.col(b).segment(at, pixels).array() * scale + shift;
      if (fused_output_relu_) y = y.max(0.0f);
    }
  }
  return output_;
}

void BatchNorm2d::BackwardImpl(const Matrix& grad_out, bool input_grad) {
  RL_CHECK(input_ != nullptr) << Describe() << ": Backward() before Forward()";
  const Matrix& x = *input_;
  const auto batch = static_cast<int>(x.cols());
  RL_CHECK(grad_out.rows() == x.rows() && grad_out.cols() == batch)
      << Describe() << " got an output gradient of " << grad_out.rows() << "x" << grad_out.cols()
      << " for a batch of " << batch;
  const int channels = shape_.channels;
  const int pixels = shape_.height * shape_.width;
  const auto n = static_cast<float>(static_cast<int64_t>(batch) * pixels);

  // Per channel: sum(dy) = d(bias) and sum(dy * xhat) = d(weight), xhat = (x - mean) inv_std.
  sum_dy_.setZero();
  sum_dy_xhat_.setZero();
  for (int b = 0; b < batch; ++b) {
    for (int c = 0; c < channels; ++c) {
      const int64_t at = static_cast<int64_t>(c) * pixels;
      const auto dy = grad_out.col(b).segment(at, pixels).array();
      const auto xs = x.col(b).segment(at, pixels).array();
      sum_dy_[c] += dy.sum();
      sum_dy_xhat_[c] += (dy * (xs - mean_[c])).sum() * inv_std_[c];
    }
  }
  bias_grad_.col(0) += sum_dy_;
  weight_grad_.col(0) += sum_dy_xhat_;
  if (!input_grad) return;

  // With batch statistics the mean and variance depend on x too:
  //   dx = weight inv_std (dy - sum(dy) / N - xhat sum(dy xhat) / N);
  // with running statistics dx = weight inv_std dy.
  grad_input_.resize(x.rows(), batch);
  for (int b = 0; b < batch; ++b) {
    for (int c = 0; c < channels; ++c) {
      const int64_t at = static_cast<int64_t>(c) * pixels;
      const float scale = weight_(c, 0) * inv_std_[c];
      const auto dy = grad_out.col(b).segment(at, pixels).array();
      auto dx = grad_input_.col(b).segment(at, pixels).array();
      if (batch_stats_) {
        const float mean_dy = sum_dy_[c] / n;
        const float k = sum_dy_xhat_[c] / n * inv_std_[c];
        const auto xs = x.col(b).segment(at, pixels).array();
        dx = scale * (dy - mean_dy - (xs - mean_[c]) * k);
      } else {
        dx = scale * dy;
      }
    }
  }
}

const Matrix& BatchNorm2d::Backward(const Matrix& grad_out) {
  BackwardImpl(grad_out, /*input_grad=*/true);
  return grad_input_;
}

void BatchNorm2d::BackwardParams(const Matrix& grad_out) {
  BackwardImpl(grad_out, /*input_grad=*/false);
}

std::vector<Param> BatchNorm2d::Params() {
  return {{"weight", &weight_, &weight_grad_}, {"bias", &bias_, &bias_grad_}};
}

std::vector<Buffer> BatchNorm2d::Buffers() {
  return {{"running_mean", &running_mean_}, {"running_var", &running_var_}};
}

std::string BatchNorm2d::Describe() const {
  return "batchnorm2d(" + std::to_string(shape_.channels) + "," + std::to_string(shape_.height) +
         "," + std::to_string(shape_.width) + ")";
}

std::unique_ptr<Layer> BatchNorm2d::Clone() const {
  auto copy = std::make_unique<BatchNorm2d>(shape_.channels, shape_.height, shape_.width);
  copy->weight_ = weight_;
  copy->bias_ = bias_;
  copy->running_mean_ = running_mean_;
  copy->running_var_ = running_var_;
  copy->training_ = training_;
  return copy;
}

}  // namespace rl::nn
