// Kernel tests run once per kernel path (nn/precision.h), and the bf16 reference they compare
// bf16 products with.
#pragma once

#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "nn/gemm.h"
#include "nn/precision.h"
#include "nn/tensor.h"
#include "tests/nn/gradient_check.h"

namespace rl::nn {

/// A fixture whose tests run on the kernel path named by the parameter: skipped, saying so, when
/// this CPU cannot run it; the automatic choice is restored afterwards. Derive a suite from it and
/// instantiate it with RL_INSTANTIATE_KERNEL_PATHS(Suite).
class KernelPathTest : public ::testing::TestWithParam<std::string> {
 protected:
  void SetUp() override {
    const std::vector<std::string> runnable = RunnableKernelPaths();
    if (std::find(runnable.begin(), runnable.end(), GetParam()) == runnable.end()) {
      GTEST_SKIP() << "this CPU cannot run the " << GetParam() << " kernels ("
                   << CpuFeatureSummary() << ")";
    }
    SetKernelPath(GetParam());
  }
  void TearDown() override { SetKernelPath("auto"); }
};

/// The test name suffix of a path: its name.
inline std::string KernelPathName(const ::testing::TestParamInfo<std::string>& path) {
  return path.param;
}

#define RL_INSTANTIATE_KERNEL_PATHS(Suite)                                             \
  INSTANTIATE_TEST_SUITE_P(Paths, Suite, ::testing::ValuesIn(::rl::nn::KernelPaths()), \
                           ::rl::nn::KernelPathName)

/// The operands of a product checked in every way Gemm() is called: m x k times k x n, a row bias,
/// a column bias and a start value of the result.
struct GemmOperands {
  Matrix a, b, bias, col_bias, start;
  GemmOperands(int m, int n, int k, std::mt19937* rng)
      : a(RandomMatrix(m, k, rng)),
        b(RandomMatrix(k, n, rng)),
        bias(RandomMatrix(m, 1, rng)),
        col_bias(RandomMatrix(n, 1, rng)),
        start(RandomMatrix(m, n, rng)) {}
};

/// What Gemm() gives for one of the 64 ways of calling it (the bits of `mode`: a transposed, b
/// transposed, the result transposed, accumulation into `start`, the row bias, the column bias),
/// and in `offset` what the biases and the start add to a * b, in `offset_scale` the sum of
/// their magnitudes.
inline Matrix GemmInMode(const GemmOperands& o, int mode, Precision precision,
                         internal::GemmWorkspace* workspace, Matrix* offset, Matrix* offset_scale) {
  const bool trans_a = (mode & 1) != 0;
  const bool trans_b = (mode & 2) != 0;
  const bool trans_c = (mode & 4) != 0;
  const bool accumulate = (mode & 8) != 0;
  const bool with_bias = (mode & 16) != 0;
  const bool with_col_bias = (mode & 32) != 0;
  const Matrix a_t = o.a.transpose();
  const Matrix b_t = o.b.transpose();
  Matrix c = o.start;
  Matrix c_t = o.start.transpose();
  const internal::ConstView va = trans_a ? internal::View(a_t).Transposed() : internal::View(o.a);
  const internal::ConstView vb = trans_b ? internal::View(b_t).Transposed() : internal::View(o.b);
  const internal::MutView vc = trans_c ? internal::View(&c_t).Transposed() : internal::View(&c);
  internal::Epilogue epilogue;
  epilogue.row_bias = with_bias ? o.bias.data() : nullptr;
  epilogue.col_bias = with_col_bias ? o.col_bias.data() : nullptr;
  internal::Gemm(va, vb, vc, accumulate, epilogue, workspace, precision);
  *offset = Matrix::Zero(c.rows(), c.cols());
  *offset_scale = Matrix::Zero(c.rows(), c.cols());
  if (with_bias) {
    offset->colwise() += o.bias.col(0);
    offset_scale->colwise() += o.bias.col(0).cwiseAbs();
  }
  if (with_col_bias) {
    offset->rowwise() += o.col_bias.col(0).transpose();
    offset_scale->rowwise() += o.col_bias.col(0).cwiseAbs().transpose();
  }
  if (accumulate) {
    *offset += o.start;
    *offset_scale += o.start.cwiseAbs();
  }
  return trans_c ? Matrix(c_t.transpose()) : c;
}

/// Calls check(mode, got, offset, offset_scale) with GemmInMode()'s result and offsets for each
/// of the 64 ways of calling Gemm() on `o` in `precision`, one workspace shared by all.
template <typename Check>
void ForEachGemmMode(const GemmOperands& o, Precision precision, Check&& check) {
  internal::GemmWorkspace workspace;
  for (int mode = 0; mode < 64; ++mode) {
    Matrix offset, offset_scale;
    const Matrix got = GemmInMode(o, mode, precision, &workspace, &offset, &offset_scale);
    check(mode, got, offset, offset_scale);
  }
}

/// The matrix with every entry rounded to bfloat16 (RoundToBf16).
inline Matrix RoundedToBf16(const Matrix& m) { return m.unaryExpr(&RoundToBf16); }

/// The bf16 reference: the product of the inputs rounded to bfloat16, summed in double.
inline Matrix Bf16Product(const Matrix& a, const Matrix& b) {
  return (RoundedToBf16(a).cast<double>() * RoundedToBf16(b).cast<double>()).cast<float>();
}

/// Sum over the shared dimension of |a_ik| |b_kj|, in double: the scale of each result's rounding
/// error.
inline Matrix AbsProduct(const Matrix& a, const Matrix& b) {
  return (a.cwiseAbs().cast<double>() * b.cwiseAbs().cast<double>()).cast<float>();
}

/// The largest |got - want| / (bound_scale * abs_product + tiny) over the entries: at most 1 when
/// every entry is within its bound.
inline double WorstBoundRatio(const Matrix& got, const Matrix& want, const Matrix& abs_product,
                              double bound_scale) {
  double worst = 0;
  for (Eigen::Index i = 0; i < got.size(); ++i) {
    const double err = std::abs(static_cast<double>(got.data()[i]) - want.data()[i]);
    const double bound = bound_scale * abs_product.data()[i] + 1e-30;
    worst = std::max(worst, err / bound);
  }
  return worst;
}

/// The two bounds of a bf16 product with a shared dimension of k (see nn/README.md, "Kernels and
/// precision"):
///  - against the bf16 reference (same rounded inputs; products of two bfloat16 are exact in
///    fp32, so only the order and rounding of the fp32 sums differ):
///    |c - ref| <= (k + 2) 2^-24 sum_k |a_ik| |b_kj|. Sharp: one product missing, doubled or
///    paired with the wrong partner exceeds it.
///  - against the exact product of the fp32 inputs: each input has a relative rounding error of
///    at most 2^-8, so each product one of at most 2 2^-8 + 2^-16, and the fp32 sums add
///    (k + 2) 2^-24: |c - a b| <= c_k 2^-8 sum_k |a_ik| |b_kj| with c_k = 2 + 2^-8 + (k + 2)
///    2^-16.
inline double SharpBf16Bound(int k) { return (k + 2) * std::ldexp(1.0, -24); }
inline double Bf16Bound(int k) {
  return (2.0 + std::ldexp(1.0, -8) + (k + 2) * std::ldexp(1.0, -16)) * std::ldexp(1.0, -8);
}

}  // namespace rl::nn
