#include "nn/activations.h"

#include "common/check.h"

namespace rl::nn {

const Matrix& ReLU::Forward(const Matrix& x) {
  own_output_.resize(x.rows(), x.cols());
  own_output_.array() = x.array().max(0.0f);
  adopted_output_ = nullptr;
  return own_output_;
}

const Matrix& ReLU::Backward(const Matrix& grad_out) {
  const Matrix& y = adopted_output_ != nullptr ? *adopted_output_ : own_output_;
  RL_CHECK(grad_out.rows() == y.rows() && grad_out.cols() == y.cols())
      << "relu: output gradient is " << grad_out.rows() << "x" << grad_out.cols() << ", output was "
      << y.rows() << "x" << y.cols();
  grad_input_.resize(grad_out.rows(), grad_out.cols());
  grad_input_.array() = (y.array() > 0.0f).select(grad_out.array(), 0.0f);
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

}  // namespace rl::nn
