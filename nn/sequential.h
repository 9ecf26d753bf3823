// A feed-forward network: a chain of layers, plus parameter bookkeeping (flat copies, target
// network updates) and allocation-free single-observation inference for actors.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "nn/layer.h"
#include "nn/tensor.h"

namespace rl::nn {

class ReLU;

/// Layers applied in order. Owns its layers; copying deep-copies the parameters.
///
/// Params() pointers stay valid while the network lives, including across moves and
/// CopyParamsFrom/SoftUpdateFrom/SetFlat, but NOT across copy-assignment (which replaces the
/// layers). Optimizers hold such pointers, so update a target network with CopyParamsFrom().
/// Not thread-safe: give each thread its own copy.
///
/// ReLUs next to Linear layers are fused into them: a Linear followed by a ReLU applies it to its
/// output, and a Linear preceded by a ReLU masks its input gradient, which saves two passes over
/// the activations. Results are the same; calling a fused layer's Forward() or Backward()
/// directly through layer() gives the fused result.
class Sequential {
 public:
  Sequential() = default;
  Sequential(const Sequential& other);
  Sequential& operator=(const Sequential& other);
  Sequential(Sequential&&) noexcept = default;
  Sequential& operator=(Sequential&&) noexcept = default;
  ~Sequential() = default;

  /// Appends a layer. Throws std::invalid_argument if its input size does not match the output
  /// size of the network so far.
  void Add(std::unique_ptr<Layer> layer);

  /// Runs the batch `x` (InputSize() x batch) through all layers and returns the last layer's
  /// output buffer (OutputSize() x batch), valid until the next Forward/Predict/Argmax. `x` must
  /// stay alive and unchanged until Backward() (see Layer).
  const Matrix& Forward(const Matrix& x);
  /// Back-propagates d(loss)/d(output) of the last Forward(); ADDS into the parameter gradients
  /// and returns d(loss)/d(input).
  const Matrix& Backward(const Matrix& grad_out);
  /// As Backward() but without d(loss)/d(input), which training does not need: saves the
  /// input-gradient product of the first layer.
  void BackwardParams(const Matrix& grad_out);
  /// Sets every parameter gradient to zero.
  void ZeroGrad();

  /// All parameters, layer by layer, named "<layer index>.<name>" as in a PyTorch state_dict
  /// (e.g. "0.weight", "0.bias", "2.weight").
  std::vector<Param> Params() { return params_; }
  /// Comma-separated layer descriptions, e.g.
  /// "linear(4,120),relu,linear(120,84),relu,linear(84,2)".
  std::string Architecture() const { return architecture_; }
  /// Total number of parameter floats.
  int64_t NumParams() const { return num_params_; }

  /// Writes all parameters, in Params() order, each in column-major order, into `out` (resized
  /// to NumParams()).
  void GetFlat(std::vector<float>* out) const;
  /// Inverse of GetFlat(). Throws std::invalid_argument if n != NumParams().
  void SetFlat(const float* data, size_t n);
  /// Copies the parameters of `other`, which must have the same architecture (checked).
  void CopyParamsFrom(const Sequential& other);
  /// this = tau * other + (1 - tau) * this, parameter-wise (Polyak averaging). Same architecture
  /// required (checked).
  void SoftUpdateFrom(const Sequential& other, float tau);

  /// Input features expected by the first sized layer (0 for a network without one).
  int InputSize() const { return input_size_; }
  /// Output features of the last sized layer (0 for a network without one).
  int OutputSize() const { return output_size_; }

  /// Q values for one observation of `obs_size` (== InputSize()) floats: the OutputSize() x 1
  /// output buffer, valid until the next forward pass. Does not allocate after the first call.
  const Matrix& Predict(const float* obs, int obs_size);
  /// Index of the largest output for one observation (the first on ties); as Predict().
  int Argmax(const float* obs, int obs_size);

  int num_layers() const { return static_cast<int>(layers_.size()); }
  Layer& layer(int i) { return *layers_[static_cast<size_t>(i)]; }
  const Layer& layer(int i) const { return *layers_[static_cast<size_t>(i)]; }

 private:
  std::vector<std::unique_ptr<Layer>> layers_;
  std::vector<Param>
      params_;  // Cached Params(); the layers are heap objects, so it survives moves.
  std::string architecture_;
  int64_t num_params_ = 0;
  int input_size_ = 0;
  int output_size_ = 0;
  Matrix observation_;  // The 1-column input of Predict().
  // Per layer: a ReLU whose output the preceding Linear computes (Forward() only records it), or
  // null; and whether the following Linear does its Backward().
  std::vector<ReLU*> fused_forward_;
  std::vector<bool> fused_backward_;
};

/// Builds a network from an architecture string, the inverse of Sequential::Architecture():
/// comma-separated layers "linear(in,out)", "relu" or "tanh" (spaces allowed). Parameters are
/// drawn from `rng` as in PyTorch's defaults. Throws std::invalid_argument naming the offending
/// layer if the string is empty, malformed, names an unknown layer or chains mismatched sizes.
Sequential BuildFromArchitecture(const std::string& arch, std::mt19937* rng);

/// A multi-layer perceptron in -> hidden[0] -> ... -> out with ReLU after every hidden layer,
/// e.g. MakeMlp(4, {120, 84}, 2, &rng). Throws std::invalid_argument on a non-positive size.
Sequential MakeMlp(int in, const std::vector<int>& hidden, int out, std::mt19937* rng);

}  // namespace rl::nn
