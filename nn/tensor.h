// Basic types of the nn library. Activations are column-major matrices with one feature per row and
// one sample per column: a batch of 128 CartPole observations is a 4 x 128 Matrix.
#pragma once

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

/// A trainable tensor and its gradient, both owned by a layer. The pointers stay valid for as long
/// as the layer lives; the shapes never change after construction.
struct Param {
  std::string name;  ///< e.g. "0.weight", "2.bias" (layer index in the network, then the tensor).
  Matrix* value;     ///< The parameter.
  Matrix* grad;      ///< Same shape as `value`; layers accumulate into it in Backward().
};

}  // namespace rl::nn
