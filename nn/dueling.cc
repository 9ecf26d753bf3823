#include "nn/dueling.h"

#include <stdexcept>
#include <string>

#include "common/check.h"

namespace rl::nn {
namespace {

std::string DuelingName(int in_features, int hidden, int num_actions) {
  return "dueling(" + std::to_string(in_features) + "," + std::to_string(hidden) + "," +
         std::to_string(num_actions) + ")";
}

// Checks the sizes before any Linear is built, so that the error names the dueling layer.
int CheckedSize(int size, int in_features, int hidden, int num_actions) {
  if (in_features <= 0 || hidden <= 0 || num_actions <= 0) {
    throw std::invalid_argument(DuelingName(in_features, hidden, num_actions) +
                                ": sizes must be positive");
  }
  return size;
}

}  // namespace

Dueling::Dueling(int in_features, int hidden, int num_actions, std::mt19937* rng)
    : value_hidden_(CheckedSize(in_features, in_features, hidden, num_actions), hidden, rng),
      value_out_(hidden, 1, rng),
      advantage_hidden_(in_features, hidden, rng),
      advantage_out_(hidden, num_actions, rng) {
  FuseHiddenRelus();
}

Dueling::Dueling(const Linear& value_hidden, const Linear& value_out,
                 const Linear& advantage_hidden, const Linear& advantage_out)
    : value_hidden_(value_hidden.weight(), value_hidden.bias()),
      value_out_(value_out.weight(), value_out.bias()),
      advantage_hidden_(advantage_hidden.weight(), advantage_hidden.bias()),
      advantage_out_(advantage_out.weight(), advantage_out.bias()) {
  FuseHiddenRelus();
}

void Dueling::FuseHiddenRelus() {
  value_hidden_.set_fused_output_relu(true);
  value_out_.set_fused_input_relu_grad(true);
  advantage_hidden_.set_fused_output_relu(true);
  advantage_out_.set_fused_input_relu_grad(true);
}

bool Dueling::FuseInputReluGrad() {
  // Both streams mask their input gradient; the sum of the masked gradients is the masked sum.
  value_hidden_.set_fused_input_relu_grad(true);
  advantage_hidden_.set_fused_input_relu_grad(true);
  return true;
}

const Matrix& Dueling::Forward(const Matrix& x) {
  const Matrix& value = value_out_.Forward(value_hidden_.Forward(x));
  const Matrix& advantage = advantage_out_.Forward(advantage_hidden_.Forward(x));
  // Q = V + A - mean(A), column by column.
  output_.resize(advantage.rows(), advantage.cols());
  const auto inv_actions = 1.0f / static_cast<float>(advantage.rows());
  for (Eigen::Index j = 0; j < advantage.cols(); ++j) {
    const float shift = value(0, j) - advantage.col(j).sum() * inv_actions;
    output_.col(j).array() = advantage.col(j).array() + shift;
  }
  return output_;
}

void Dueling::BackwardHead(const Matrix& grad_out) {
  RL_CHECK(grad_out.rows() == output_.rows() && grad_out.cols() == output_.cols())
      << Describe() << " got an output gradient of " << grad_out.rows() << "x" << grad_out.cols()
      << ", output was " << output_.rows() << "x" << output_.cols();
  // dQ_i/dV = 1 and dQ_i/dA_k = [i == k] - 1 / num_actions.
  const auto batch = grad_out.cols();
  const auto inv_actions = 1.0f / static_cast<float>(grad_out.rows());
  grad_value_.resize(1, batch);
  grad_advantage_.resize(grad_out.rows(), batch);
  for (Eigen::Index j = 0; j < batch; ++j) {
    const float sum = grad_out.col(j).sum();
    grad_value_(0, j) = sum;
    grad_advantage_.col(j).array() = grad_out.col(j).array() - sum * inv_actions;
  }
  grad_value_hidden_ = &value_out_.Backward(grad_value_);
  grad_advantage_hidden_ = &advantage_out_.Backward(grad_advantage_);
}

const Matrix& Dueling::Backward(const Matrix& grad_out) {
  BackwardHead(grad_out);
  grad_input_ = value_hidden_.Backward(*grad_value_hidden_);
  grad_input_ += advantage_hidden_.Backward(*grad_advantage_hidden_);
  return grad_input_;
}

void Dueling::BackwardParams(const Matrix& grad_out) {
  BackwardHead(grad_out);
  value_hidden_.BackwardParams(*grad_value_hidden_);
  advantage_hidden_.BackwardParams(*grad_advantage_hidden_);
}

std::vector<Param> Dueling::Params() {
  std::vector<Param> params;
  auto add = [&params](const std::string& prefix, Linear& layer) {
    for (Param& p : layer.Params()) {
      p.name = prefix + p.name;
      params.push_back(p);
    }
  };
  add("value.0.", value_hidden_);
  add("value.2.", value_out_);
  add("advantage.0.", advantage_hidden_);
  add("advantage.2.", advantage_out_);
  return params;
}

std::string Dueling::Describe() const {
  return DuelingName(value_hidden_.input_size(), value_hidden_.output_size(),
                     advantage_out_.output_size());
}

std::unique_ptr<Layer> Dueling::Clone() const {
  std::unique_ptr<Dueling> copy(
      new Dueling(value_hidden_, value_out_, advantage_hidden_, advantage_out_));
  copy->set_precision(precision_);
  return copy;
}

void Dueling::set_precision(Precision precision) {
  precision_ = precision;
  for (Linear* layer : {&value_hidden_, &value_out_, &advantage_hidden_, &advantage_out_}) {
    layer->set_precision(precision);
  }
}

}  // namespace rl::nn
