// The interface every layer of a Sequential network implements.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "nn/precision.h"
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
  /// internal buffer (or, for layers that do not change the data, to `x` itself) that stays valid
  /// until the next call on this layer.
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

  /// The non-trainable state tensors (e.g. running statistics), in a fixed order, named like
  /// Params(). Optimizers do not update them; the layer does, in Forward() in training mode.
  virtual std::vector<Buffer> Buffers() { return {}; }

  /// Training (the default) or evaluation mode. Only layers whose forward pass differs between
  /// the two (batch normalisation) care.
  virtual void set_training(bool /*training*/) {}

  /// The arithmetic of the layer's matrix products (nn/precision.h), fp32 until set. Layers
  /// without products ignore it; copies and Clone() keep it.
  virtual void set_precision(Precision /*precision*/) {}

  /// The layer in architecture-string form, e.g. "linear(4,120)" or "relu".
  virtual std::string Describe() const = 0;

  /// A deep copy of the parameters and buffers, in the same mode and precision (gradients zero,
  /// no cached activations, no fusion).
  virtual std::unique_ptr<Layer> Clone() const = 0;

  /// Number of input features, or 0 if the layer accepts any (element-wise layers).
  virtual int input_size() const { return 0; }
  /// Number of output features, or 0 if it equals the number of input features.
  virtual int output_size() const { return 0; }
  /// For layers that read images: the C x H x W shape of one input; empty otherwise.
  virtual ImageShape input_shape() const { return {}; }
  /// For layers that produce images: the shape of one output; empty otherwise.
  virtual ImageShape output_shape() const { return {}; }

  /// Asks the layer to apply a ReLU that follows it: on success (returns true) Forward() returns
  /// max(output, 0) from now on. Used by Sequential, which then skips the ReLU's own pass.
  virtual bool FuseOutputRelu() { return false; }
  /// Asks the layer to apply the backward pass of a ReLU that precedes it: on success (returns
  /// true) Backward() returns the gradient with respect to the ReLU's input, zero wherever this
  /// layer's input (the ReLU's output) is 0. Used by Sequential, which then skips the ReLU's
  /// Backward().
  virtual bool FuseInputReluGrad() { return false; }
};

}  // namespace rl::nn
