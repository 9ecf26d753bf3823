// Internal matrix-product kernel used by the layers for batched products. Not part of the public
// API.
//
// Eigen's general product reaches about 70 GFLOP/s on the 84x120 by 120x128 products of the DQN
// MLP (about 36 us each); this kernel about 95 (about 26 us) with 8-float vectors. It packs panels
// of up to 48 rows of the left operand and keeps a 48 x 8 block of the result in registers (16 x 6
// on the avx2 path)
// while it walks the shared dimension; products with at most 4 rows are computed as dot products
// instead. Transposed operands are read through strides, so no transposed copy of a weight or
// activation matrix is made, and the bias and a ReLU (or a ReLU's backward mask) are applied as
// results are stored. In bf16 (nn/precision.h) both operands are rounded to bfloat16 as they are
// packed, pairs of them along the shared dimension, and the AVX512_BF16 kernel keeps a 48 x 8
// block of fp32 sums in registers; without AVX512_BF16 the rounding is done on copies of the
// operands and the fp32 kernel multiplies them. The kernels are those of the path in use
// (nn/kernels.h).
#pragma once

#include <cstdint>

#include "nn/precision.h"
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

/// Rows per packed panel of the left operand of GemmPacked() in `precision` on the current path
/// (see GemmPacked()).
int PackedPanelRows(Precision precision);

/// Scratch space of a product: the kernel's (packed panels), and the operands rounded to bfloat16
/// where the CPU has no bf16 instructions and the products are emulated. It only grows, so
/// repeated calls with the same shapes and the same workspace do not allocate, whichever thread
/// runs them.
struct GemmWorkspace {
  Vector kernel;
  Vector rounded_a;
  Vector rounded_b;
};

/// c = a * b (accumulate == false) or c += a * b (accumulate == true), followed by `epilogue`,
/// the products in `precision`. `c` must not overlap `a`, `b` or the mask. `workspace` is scratch
/// space (GemmWorkspace). O(m n k). With
/// SetNumThreads(n > 1) (nn/parallel.h) a large product (at least one panel of rows and 8M
/// multiply-adds) is split into blocks of whole panels of rows (or of columns) over the threads,
/// with the same result bit for bit; the other threads use their own scratch space.
void Gemm(ConstView a, ConstView b, MutView c, bool accumulate, const Epilogue& epilogue,
          GemmWorkspace* workspace, Precision precision = Precision::kFp32);

/// As Gemm() for an m x k left operand that the caller has already packed (e.g. unfolded into
/// place by a convolution), in panels of R = PackedPanelRows(precision) rows: rows
/// [q * R, (q + 1) * R) are at a_packed + q * R * k, as k steps of R floats (row i of the panel at
/// step p is a_packed[q * R * k + p * R + i]). Rows past m in the last panel are read but do not
/// affect c. O(m n k). Split over threads as Gemm().
void GemmPacked(const float* a_packed, int m, int k, ConstView b, MutView c, bool accumulate,
                const Epilogue& epilogue, GemmWorkspace* workspace,
                Precision precision = Precision::kFp32);

/// The layout GemmPackedPairs() reads: the rows of an m x k left operand in panels of
/// R = PackedPanelRows(Precision::kBf16) rows, each ceil(k / 2) steps of R 32-bit words; word i of
/// step q of panel p holds the bfloat16 of A(p R + i, 2 q) in its low half and that of
/// A(p R + i, 2 q + 1) (0 past k) in its high half. PackedPairs(m, k) words in all.
int64_t PackedPairs(int m, int k);

/// As GemmPacked() in bf16 for a left operand already rounded and packed as bf16 pairs (e.g.
/// unfolded so by a convolution). Only where NativeBf16() (nn/precision.h); aborts elsewhere.
void GemmPackedPairs(const uint32_t* a_pairs, int m, int k, ConstView b, MutView c, bool accumulate,
                     const Epilogue& epilogue, GemmWorkspace* workspace);

/// `a` rounded to bfloat16 and packed into `pairs` (PackedPairs(a.rows, a.cols) words), the layout
/// of GemmPackedPairs(): a left operand packed once for several products (Linear's weight). Only
/// where NativeBf16(); aborts elsewhere. Split over threads by panels. O(a.rows a.cols).
void RoundIntoPairs(ConstView a, uint32_t* pairs);

/// Whether Gemm(a, b, c, ..., Precision::kBf16) multiplies the bf16 pairs of `a` on the CPU's
/// instructions, so that GemmPackedPairs() of RoundIntoPairs(a) computes the same c, bit for bit.
bool GemmUsesPairs(ConstView a, ConstView b, MutView c);

/// out[i] += sum_j g(i, j) for a column-major g (the bias gradient of a batch). O(rows cols).
void AddRowSums(const Matrix& g, float* out);

}  // namespace rl::nn::internal
