// Element-wise activation layers. They cache their own output (not the input), so Backward() does
// not depend on the caller keeping the input alive.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "nn/layer.h"
#include "nn/tensor.h"

namespace rl::nn {

/// y = max(x, 0). The gradient at x == 0 is taken as 0, as in PyTorch.
class ReLU : public Layer {
 public:
  const Matrix& Forward(const Matrix& x) override;
  const Matrix& Backward(const Matrix& grad_out) override;
  std::string Describe() const override { return "relu"; }
  std::unique_ptr<Layer> Clone() const override { return std::make_unique<ReLU>(); }

  /// Used by Sequential when the preceding layer already applied this ReLU (see
  /// Linear::set_fused_output_relu): records `y`, which must be this layer's output for the
  /// current input and must stay alive until Backward(), and returns it.
  const Matrix& AdoptOutput(const Matrix& y) {
    adopted_output_ = &y;
    return y;
  }

 private:
  const Matrix* adopted_output_ = nullptr;  // Set by AdoptOutput(), cleared by Forward().
  Matrix own_output_;
  Matrix grad_input_;
};

/// y = tanh(x); dy/dx = 1 - y^2.
class Tanh : public Layer {
 public:
  const Matrix& Forward(const Matrix& x) override;
  const Matrix& Backward(const Matrix& grad_out) override;
  std::string Describe() const override { return "tanh"; }
  std::unique_ptr<Layer> Clone() const override { return std::make_unique<Tanh>(); }

 private:
  Matrix output_;
  Matrix grad_input_;
};

/// y_i = low_i + (tanh(x_i) + 1) / 2 * (high_i - low_i): a tanh squashed into per-feature bounds,
/// the output layer of a deterministic actor (TD3) whose action box is not [-1, 1] in every
/// dimension (CarRacing: steer [-1, 1], gas and brake [0, 1]). Architecture string
/// "bounded(n,low_1,high_1,...,low_n,high_n)", the bounds printed so that they read back exactly.
class Bounded : public Layer {
 public:
  /// Throws std::invalid_argument unless low and high have the same positive size and every
  /// low_i < high_i, both finite.
  Bounded(std::vector<float> low, std::vector<float> high);
  const Matrix& Forward(const Matrix& x) override;
  const Matrix& Backward(const Matrix& grad_out) override;
  std::string Describe() const override;
  std::unique_ptr<Layer> Clone() const override { return std::make_unique<Bounded>(*this); }
  int input_size() const override { return static_cast<int>(low_.size()); }
  int output_size() const override { return static_cast<int>(low_.size()); }
  const std::vector<float>& low() const { return low_; }
  const std::vector<float>& high() const { return high_; }

 private:
  std::vector<float> low_, high_;
  Vector mid_, half_;  // (high + low) / 2, (high - low) / 2
  Matrix tanh_;        // tanh(x) of the last Forward
  Matrix output_;
  Matrix grad_input_;
};

}  // namespace rl::nn
