// Flatten: the boundary between the convolutional and the fully connected part of a network.
#pragma once

#include <memory>
#include <string>

#include "nn/layer.h"
#include "nn/tensor.h"

namespace rl::nn {

/// The identity. Images are already stored flattened (channel-major columns, see ImageShape), so
/// this layer only marks, in architecture strings, where a network stops treating its features
/// as images, as nn.Flatten does in PyTorch. Forward() returns its input and Backward() the
/// output gradient, without copying.
class Flatten : public Layer {
 public:
  const Matrix& Forward(const Matrix& x) override { return x; }
  const Matrix& Backward(const Matrix& grad_out) override { return grad_out; }
  std::string Describe() const override { return "flatten"; }
  std::unique_ptr<Layer> Clone() const override { return std::make_unique<Flatten>(); }
};

}  // namespace rl::nn
