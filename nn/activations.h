// Element-wise activation layers. They cache their own output (not the input), so Backward() does
// not depend on the caller keeping the input alive.
#pragma once

#include <memory>
#include <string>

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

}  // namespace rl::nn
