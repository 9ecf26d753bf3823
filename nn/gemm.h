// Internal matrix-product kernel used by the layers for batched products. Not part of the public
// API.
//
// Eigen's general product reaches about 70 GFLOP/s on the 84x120 by 120x128 products of the DQN
// MLP (about 36 us each); this kernel about 95 (about 26 us). It packs panels of up to 24 rows of
// the left operand and keeps a 24 x 8 block of the result in registers (16 x 6 without AVX-512)
// while it walks the shared dimension; products with at most 4 rows are computed as dot products
// instead. Transposed operands are read through strides, so no transposed copy of a weight or
// activation matrix is made, and the bias and a ReLU (or a ReLU's backward mask) are applied as
// results are stored.
#pragma once

#include <cstdint>

#include "nn/tensor.h"

namespace rl::nn::internal {

/// A read-only strided view: element (i, j) is data[i * row_stride + j * col_stride].
struct ConstView {
  const float* data;
  int rows;
  int cols;
  int64_t row_stride;
  int64_t col_stride;

  ConstView Transposed() const { return {data, cols, rows, col_stride, row_stride}; }
};

/// A writable strided view, as ConstView.
struct MutView {
  float* data;
  int rows;
  int cols;
  int64_t row_stride;
  int64_t col_stride;

  MutView Transposed() const { return {data, cols, rows, col_stride, row_stride}; }
};

inline ConstView View(const Matrix& m) {
  return {m.data(), static_cast<int>(m.rows()), static_cast<int>(m.cols()), 1, m.rows()};
}
inline MutView View(Matrix* m) {
  return {m->data(), static_cast<int>(m->rows()), static_cast<int>(m->cols()), 1, m->rows()};
}

/// Whether Gemm() is expected to beat Eigen for an (m x k) * (k x n) product. False for
/// matrix-vector products and tiny problems, where packing does not pay off.
bool PreferGemm(int m, int n, int k);

/// Element-wise steps applied to each result of Gemm() before it is stored, in this order.
struct Epilogue {
  const float* row_bias = nullptr;  ///< c.rows floats; row_bias[i] is added to row i of c.
  const float* col_bias = nullptr;  ///< c.cols floats; col_bias[j] is added to column j of c.
  bool relu = false;                ///< Store max(result, 0) (a fused ReLU forward).
  /// Laid out like c (same strides): store 0 where mask <= 0 (a fused ReLU backward, the mask
  /// being the ReLU's output).
  const float* mask = nullptr;
};

/// Rows per packed panel of the left operand (see GemmPacked()).
#if defined(__AVX512F__)
constexpr int kPanelRows = 24;
#elif defined(__AVX__)
constexpr int kPanelRows = 16;
#else
constexpr int kPanelRows = 8;
#endif

/// c = a * b (accumulate == false) or c += a * b (accumulate == true), followed by `epilogue`.
/// `c` must not overlap `a`, `b` or the mask. `workspace` is scratch space; it only grows, so
/// repeated calls with the same shapes do not allocate. O(m n k). With SetNumThreads(n > 1)
/// (nn/parallel.h) a large product (at least 24 rows and 8M multiply-adds) is split into blocks of
/// whole 24-row panels (or of columns) over the threads, with the same result bit for bit; the
/// other threads use their own scratch space.
void Gemm(ConstView a, ConstView b, MutView c, bool accumulate, const Epilogue& epilogue,
          Vector* workspace);

/// As Gemm() for an m x k left operand that the caller has already packed (e.g. unfolded into
/// place by a convolution): rows [q * kPanelRows, (q + 1) * kPanelRows) are at
/// a_packed + q * kPanelRows * k, as k steps of kPanelRows floats (row i of the panel at step p
/// is a_packed[q * kPanelRows * k + p * kPanelRows + i]). Rows past m in the last panel are read
/// but do not affect c. O(m n k). Split over threads as Gemm().
void GemmPacked(const float* a_packed, int m, int k, ConstView b, MutView c, bool accumulate,
                const Epilogue& epilogue, Vector* workspace);

/// out[i] += sum_j g(i, j) for a column-major g (the bias gradient of a batch). O(rows cols).
void AddRowSums(const Matrix& g, float* out);

}  // namespace rl::nn::internal
