// The interface every layer of a Sequential network implements.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "nn/tensor.h"

namespace rl::nn {

/// A differentiable map from an in_features x batch matrix to an out_features x batch matrix.
///
/// Layers own their output and input-gradient buffers and reuse them across calls, so once the
/// batch size is stable Forward() and Backward() do not allocate. Backward() uses what the most
/// recent Forward() cached; a layer may keep a pointer to the input of Forward(), so that input
/// must stay alive and unchanged until the matching Backward(). Layers are not thread-safe.
class Layer {
 public:
  virtual ~Layer() = default;

  /// Computes the output for the batch `x` (one sample per column). Returns a reference to an
  /// internal buffer that stays valid until the next call on this layer.
  virtual const Matrix& Forward(const Matrix& x) = 0;

  /// Given d(loss)/d(output) of the last Forward(), ADDS d(loss)/d(parameters) into the parameter
  /// gradients and returns d(loss)/d(input) (an internal buffer).
  virtual const Matrix& Backward(const Matrix& grad_out) = 0;

  /// As Backward() for a layer whose input gradient nobody needs (the first layer of a network):
  /// ADDS the parameter gradients; layers may skip computing d(loss)/d(input). The default calls
  /// Backward().
  virtual void BackwardParams(const Matrix& grad_out) { Backward(grad_out); }

  /// The trainable tensors, in a fixed order. Names carry no layer index (e.g. "weight"); the
  /// network prefixes them.
  virtual std::vector<Param> Params() { return {}; }

  /// The layer in architecture-string form, e.g. "linear(4,120)" or "relu".
  virtual std::string Describe() const = 0;

  /// A deep copy of the parameters (gradients zero, no cached activations).
  virtual std::unique_ptr<Layer> Clone() const = 0;

  /// Number of input features, or 0 if the layer accepts any (element-wise layers).
  virtual int input_size() const { return 0; }
  /// Number of output features, or 0 if it equals the number of input features.
  virtual int output_size() const { return 0; }
};

}  // namespace rl::nn
