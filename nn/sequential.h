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
/// ReLUs are fused into the layers next to them that support it (Linear, Conv2d, BatchNorm2d,
/// Dueling; see Layer::FuseOutputRelu): a layer followed by a ReLU applies it to its output, and a
/// layer preceded by a ReLU masks its input gradient, which saves two passes over the
/// activations. Results are the same; calling a fused layer's Forward() or Backward() directly
/// through layer() gives the fused result.
///
/// State comes in two kinds: parameters (Params(), trainable, what optimizers update) and buffers
/// (Buffers(), e.g. the running statistics of BatchNorm2d, updated by Forward() in training
/// mode). GetFlat()/SetFlat(), CopyParamsFrom()/SoftUpdateFrom() and therefore checkpoints and
/// the parameters sent to actors carry both, parameters first, so an actor normalises with the
/// learner's running statistics. The network starts in training mode; see set_training().
class Sequential {
 public:
  Sequential() = default;
  Sequential(const Sequential& other);
  Sequential& operator=(const Sequential& other);
  Sequential(Sequential&&) noexcept = default;
  Sequential& operator=(Sequential&&) noexcept = default;
  ~Sequential() = default;

  /// Appends a layer, in the network's current mode. Throws std::invalid_argument if its input
  /// size does not match the output size of the network so far, or if it reads images of another
  /// shape than the last image-producing layer makes.
  void Add(std::unique_ptr<Layer> layer);

  /// Training mode (the default) or evaluation mode, for every layer: in evaluation mode
  /// BatchNorm2d normalises with its running statistics and does not update them. As PyTorch's
  /// module.train(bool) / module.eval().
  void set_training(bool training);
  bool training() const { return training_; }

  /// The arithmetic of every layer's matrix products (nn/precision.h), fp32 until set; layers
  /// added later take it too. Copies keep it.
  void set_precision(Precision precision);
  Precision precision() const { return precision_; }

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

  /// All trainable parameters, layer by layer, named "<layer index>.<name>" as in a PyTorch
  /// state_dict (e.g. "0.weight", "0.bias", "2.weight"). Give these to an optimizer.
  std::vector<Param> Params() { return params_; }
  /// All buffers (non-trainable state such as "1.running_mean", "1.running_var"), layer by layer,
  /// named as Params(). Empty for networks without batch normalisation.
  std::vector<Buffer> Buffers() { return buffers_; }
  /// Comma-separated layer descriptions, e.g.
  /// "linear(4,120),relu,linear(120,84),relu,linear(84,2)".
  std::string Architecture() const { return architecture_; }
  /// Total number of trainable parameter floats (PyTorch's sum of p.numel() over parameters()).
  int64_t NumParams() const { return num_params_; }
  /// Total number of buffer floats.
  int64_t NumBuffers() const { return num_buffers_; }
  /// NumParams() + NumBuffers(): the length of GetFlat().
  int64_t FlatSize() const { return num_params_ + num_buffers_; }

  /// Writes all parameters, in Params() order, then all buffers, in Buffers() order, each in
  /// column-major order, into `out` (resized to FlatSize()). Without buffers this is just the
  /// parameters; with them, the first NumParams() floats still are.
  void GetFlat(std::vector<float>* out) const;
  /// Inverse of GetFlat(). Throws std::invalid_argument if n != FlatSize().
  void SetFlat(const float* data, size_t n);
  /// Copies the parameters and buffers of `other`, which must have the same architecture
  /// (checked).
  void CopyParamsFrom(const Sequential& other);
  /// this = tau * other + (1 - tau) * this, for every parameter and buffer (Polyak averaging; a
  /// blend of running variances is still a valid variance estimate). Same architecture required
  /// (checked).
  void SoftUpdateFrom(const Sequential& other, float tau);

  /// Input features expected by the first sized layer (0 for a network without one).
  int InputSize() const { return input_size_; }
  /// Output features of the last sized layer (0 for a network without one).
  int OutputSize() const { return output_size_; }

  /// Q values for one observation of `obs_size` (== InputSize()) floats: the OutputSize() x 1
  /// output buffer, valid until the next forward pass. Does not allocate after the first call.
  /// Always runs in evaluation mode (batch normalisation uses, and keeps, the running statistics:
  /// the statistics of a single observation mean nothing), whatever training() says.
  const Matrix& Predict(const float* obs, int obs_size);
  /// Index of the largest output for one observation (the first on ties); as Predict().
  int Argmax(const float* obs, int obs_size);

  /// The input of layer `i` in the last Forward(), Predict() or Argmax(): for i = 0 the batch
  /// given (Predict()'s own copy of the observation), else what layer i - 1 returned, a fused ReLU
  /// included (the input of a layer after a ReLU is the ReLU's output). Reads the activations of
  /// a hidden layer without another pass, e.g. LayerInput(num_layers() - 1), the features the
  /// last layer sees. The reference is valid until the next forward pass and only while the
  /// network is not moved or assigned. Throws std::out_of_range unless 0 <= i < num_layers(), and
  /// std::logic_error before the first forward pass. O(1).
  const Matrix& LayerInput(int i) const;

  int num_layers() const { return static_cast<int>(layers_.size()); }
  Layer& layer(int i) { return *layers_[static_cast<size_t>(i)]; }
  const Layer& layer(int i) const { return *layers_[static_cast<size_t>(i)]; }

 private:
  std::vector<std::unique_ptr<Layer>> layers_;
  // Cached Params() and Buffers(); the layers are heap objects, so they survive moves.
  std::vector<Param> params_;
  std::vector<Buffer> buffers_;
  std::string architecture_;
  int64_t num_params_ = 0;
  int64_t num_buffers_ = 0;
  int input_size_ = 0;
  int output_size_ = 0;
  ImageShape image_;  // Output shape of the last layer that produces images, if any since.
  bool training_ = true;
  Precision precision_ = Precision::kFp32;
  Matrix observation_;  // The 1-column input of Predict().
  // Per layer: a ReLU whose output the preceding layer computes (Forward() only records it), or
  // null; and whether the following layer does its Backward().
  std::vector<ReLU*> fused_forward_;
  std::vector<bool> fused_backward_;
  // Per layer: its input in the last Forward() (LayerInput()); null before the first.
  std::vector<const Matrix*> inputs_;
};

/// Builds a network from an architecture string, the inverse of Sequential::Architecture():
/// comma-separated layers (spaces allowed), each one of
///   linear(in,out)                                   Linear
///   conv2d(in_c,out_c,kernel,stride,padding,h,w)     Conv2d on in_c x h x w images
///   batchnorm2d(channels,h,w)                        BatchNorm2d
///   layernorm(features)                              LayerNorm
///   dueling(in,hidden,actions)                       Dueling
///   maxpool2d(channels,k,h,w), avgpool2d(channels,k,h,w)  Pool2d (k x k windows, stride k)
///   bounded(n,low_1,high_1,...,low_n,high_n)         Bounded (tanh scaled to per-feature bounds)
///   relu, tanh, flatten
/// e.g. "conv2d(4,32,8,4,0,84,84),relu,conv2d(32,64,4,2,0,20,20),relu,flatten,linear(6400,7)".
/// Parameters are drawn from `rng` as in PyTorch's defaults, layer by layer. Throws
/// std::invalid_argument naming the offending layer if the string is empty, malformed, names an
/// unknown layer, gives a wrong number of arguments, chains mismatched sizes or image shapes, or
/// exceeds a limit below (checked before anything is allocated).
Sequential BuildFromArchitecture(const std::string& arch, std::mt19937* rng);

/// Limits of BuildFromArchitecture, whose strings come from checkpoint files and weight messages:
/// far above any network of ours, and low enough that no size computation overflows and no
/// string makes a process allocate gigabytes. Any integer argument; the values of an image
/// (channels x height x width, padding included); the parameters of the whole network.
inline constexpr int kMaxArchitectureInteger = 1 << 16;
inline constexpr int64_t kMaxArchitectureImage = int64_t{1} << 26;
inline constexpr int64_t kMaxArchitectureParameters = int64_t{1} << 26;

/// A multi-layer perceptron in -> hidden[0] -> ... -> out with ReLU after every hidden layer,
/// e.g. MakeMlp(4, {120, 84}, 2, &rng). Throws std::invalid_argument on a non-positive size.
Sequential MakeMlp(int in, const std::vector<int>& hidden, int out, std::mt19937* rng);

}  // namespace rl::nn
