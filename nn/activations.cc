#include "nn/activations.h"

#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <utility>

#include "common/check.h"
#include "nn/parallel.h"

namespace rl::nn {

const Matrix& ReLU::Forward(const Matrix& x) {
  own_output_.resize(x.rows(), x.cols());
  internal::ParallelForColumns(x.cols(), x.size(), [&](int64_t begin, int64_t end) {
    const int64_t count = end - begin;
    own_output_.middleCols(begin, count).array() = x.middleCols(begin, count).array().max(0.0f);
  });
  adopted_output_ = nullptr;
  return own_output_;
}

const Matrix& ReLU::Backward(const Matrix& grad_out) {
  const Matrix& y = adopted_output_ != nullptr ? *adopted_output_ : own_output_;
  RL_CHECK(grad_out.rows() == y.rows() && grad_out.cols() == y.cols())
      << "relu: output gradient is " << grad_out.rows() << "x" << grad_out.cols() << ", output was "
      << y.rows() << "x" << y.cols();
  grad_input_.resize(grad_out.rows(), grad_out.cols());
  internal::ParallelForColumns(grad_out.cols(), grad_out.size(), [&](int64_t begin, int64_t end) {
    const int64_t count = end - begin;
    grad_input_.middleCols(begin, count).array() =
        (y.middleCols(begin, count).array() > 0.0f)
            .select(grad_out.middleCols(begin, count).array(), 0.0f);
  });
  return grad_input_;
}

const Matrix& Tanh::Forward(const Matrix& x) {
  output_.resize(x.rows(), x.cols());
  output_.array() = x.array().tanh();
  return output_;
}

const Matrix& Tanh::Backward(const Matrix& grad_out) {
  RL_CHECK(grad_out.rows() == output_.rows() && grad_out.cols() == output_.cols())
      << "tanh: output gradient is " << grad_out.rows() << "x" << grad_out.cols() << ", output was "
      << output_.rows() << "x" << output_.cols();
  grad_input_.resize(grad_out.rows(), grad_out.cols());
  grad_input_.array() = grad_out.array() * (1.0f - output_.array().square());
  return grad_input_;
}

Bounded::Bounded(std::vector<float> low, std::vector<float> high)
    : low_(std::move(low)), high_(std::move(high)) {
  if (low_.empty() || low_.size() != high_.size()) {
    throw std::invalid_argument("bounded: needs as many lows as highs, at least one");
  }
  const auto n = static_cast<Eigen::Index>(low_.size());
  mid_.resize(n);
  half_.resize(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    const float lo = low_[static_cast<size_t>(i)], hi = high_[static_cast<size_t>(i)];
    if (!std::isfinite(lo) || !std::isfinite(hi) || !(lo < hi)) {
      throw std::invalid_argument("bounded: every bound must be finite with low < high");
    }
    mid_[i] = (hi + lo) / 2;
    half_[i] = (hi - lo) / 2;
  }
}

const Matrix& Bounded::Forward(const Matrix& x) {
  RL_CHECK(x.rows() == mid_.size())
      << "bounded: input has " << x.rows() << " rows, expected " << mid_.size();
  tanh_.resize(x.rows(), x.cols());
  tanh_.array() = x.array().tanh();
  output_.resize(x.rows(), x.cols());
  // low + (t + 1) / 2 * (high - low) = mid + t * half.
  output_ = (tanh_.array().colwise() * half_.array()).colwise() + mid_.array();
  return output_;
}

const Matrix& Bounded::Backward(const Matrix& grad_out) {
  RL_CHECK(grad_out.rows() == tanh_.rows() && grad_out.cols() == tanh_.cols())
      << "bounded: output gradient is " << grad_out.rows() << "x" << grad_out.cols()
      << ", output was " << tanh_.rows() << "x" << tanh_.cols();
  grad_input_.resize(grad_out.rows(), grad_out.cols());
  grad_input_.array() =
      (grad_out.array() * (1.0f - tanh_.array().square())).colwise() * half_.array();
  return grad_input_;
}

std::string Bounded::Describe() const {
  std::string s = "bounded(" + std::to_string(low_.size());
  char buf[32];
  for (size_t i = 0; i < low_.size(); ++i) {
    std::snprintf(buf, sizeof(buf), ",%.9g", static_cast<double>(low_[i]));
    s += buf;
    std::snprintf(buf, sizeof(buf), ",%.9g", static_cast<double>(high_[i]));
    s += buf;
  }
  return s + ")";
}

}  // namespace rl::nn
