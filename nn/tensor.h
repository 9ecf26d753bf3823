// Basic types of the nn library. Activations are column-major matrices with one feature per row and
// one sample per column: a batch of 128 CartPole observations is a 4 x 128 Matrix.
#pragma once

#include <cstdint>
#include <string>

// GCC 12's AVX-512 intrinsic headers, which Eigen includes, raise a false -Wmaybe-uninitialized
// wherever their "undefined value" helpers get inlined (GCC bug 105593, fixed in GCC 13).
#if defined(__GNUC__) && !defined(__clang__) && __GNUC__ == 12
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#include <Eigen/Core>
#pragma GCC diagnostic pop
#else
#include <Eigen/Core>
#endif

namespace rl::nn {

/// A float32 column-major matrix: rows = features, cols = batch.
using Matrix = Eigen::Matrix<float, Eigen::Dynamic, Eigen::Dynamic>;
/// A float32 column vector (losses, per-sample weights).
using Vector = Eigen::VectorXf;

/// Images are stored one per column, channel-major: the pixel (channel c, row y, column x) of a
/// C x H x W image is row (c * H + y) * W + x of its column, as in a flattened PyTorch NCHW
/// tensor. A batch of B stacks of four 84 x 84 frames is a 28224 x B Matrix.
struct ImageShape {
  int channels = 0;  ///< 0 for "not an image".
  int height = 0;
  int width = 0;

  int size() const { return channels * height * width; }
  bool empty() const { return channels == 0; }
  bool operator==(const ImageShape&) const = default;
};

/// A trainable tensor and its gradient, both owned by a layer. The pointers stay valid for as long
/// as the layer lives; the shapes never change after construction.
struct Param {
  std::string name;  ///< e.g. "0.weight", "2.bias" (layer index in the network, then the tensor).
  Matrix* value;     ///< The parameter.
  Matrix* grad;      ///< Same shape as `value`; layers accumulate into it in Backward().
  /// Counts the writes of `value` (null for a parameter no layer keeps a copy of): a layer may
  /// keep a derived copy of the parameter (Linear's weight rounded and packed for bf16 products)
  /// for as long as the count has not moved. Whoever writes *value through this Param calls
  /// MarkChanged() before the layer's next Forward(); the optimizers and Sequential's writers
  /// (SetFlat, CopyParamsFrom, SoftUpdateFrom) do.
  uint64_t* version = nullptr;

  void MarkChanged() const {
    if (version != nullptr) ++*version;
  }
};

/// A non-trainable tensor that is part of a layer's state, e.g. the running statistics of a batch
/// normalisation. Optimizers never see it; Sequential::GetFlat()/SetFlat() and checkpoints carry
/// it after the parameters.
struct Buffer {
  std::string name;  ///< e.g. "1.running_mean" (layer index in the network, then the tensor).
  Matrix* value;
};

}  // namespace rl::nn
