#include "nn/gemm.h"

#include <array>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "tests/nn/gradient_check.h"
#include "tests/nn/kernel_paths.h"

namespace rl::nn::internal {
namespace {

// Every test runs on every kernel path this CPU can run.
class GemmTest : public KernelPathTest {};
RL_INSTANTIATE_KERNEL_PATHS(GemmTest);

// Compares Gemm with Eigen for c (m x n) = op(a) * op(b) (+ biases) over every combination of
// transposed operands, transposed output, accumulation, row bias and column bias.
void CheckAgainstEigen(int m, int n, int k) {
  std::mt19937 rng(static_cast<unsigned>(m * 10007 + n * 101 + k));
  const GemmOperands o(m, n, k, &rng);
  const Matrix product = o.a * o.b;
  const float tol = 1e-5f * static_cast<float>(k + 1);
  ForEachGemmMode(o, Precision::kFp32,
                  [&](int mode, const Matrix& got, const Matrix& offset, const Matrix&) {
                    EXPECT_LE((got - (product + offset)).cwiseAbs().maxCoeff(), tol)
                        << m << "x" << k << " * " << k << "x" << n << " mode " << mode;
                  });
}

TEST_P(GemmTest, MatchesEigenOnRaggedShapes) {
  for (int m : {1, 2, 3, 4, 5, 8, 17, 24, 25, 84}) {
    for (int n : {1, 2, 5, 8, 13, 32}) {
      for (int k : {1, 4, 9, 33}) CheckAgainstEigen(m, n, k);
    }
  }
}

TEST_P(GemmTest, MatchesEigenOnTheCartPoleShapes) {
  CheckAgainstEigen(120, 128, 4);
  CheckAgainstEigen(84, 128, 120);
  CheckAgainstEigen(84, 120, 128);
  CheckAgainstEigen(120, 128, 84);
}

TEST_P(GemmTest, MatchesEigenWhenTheSharedDimensionSpansSeveralSlices) {
  CheckAgainstEigen(30, 9, 600);
}

// The fused activation steps: relu(a * b + bias), and a * b zeroed where a mask is not positive,
// on every code path (dot products, panels, transposed output, several slices of k).
TEST_P(GemmTest, EpilogueAppliesReluAndMask) {
  for (const auto& [m, n, k] : {std::array<int, 3>{2, 16, 9}, std::array<int, 3>{30, 17, 40},
                                std::array<int, 3>{5, 40, 7}, std::array<int, 3>{12, 9, 300}}) {
    std::mt19937 rng(static_cast<unsigned>(m + n + k));
    GemmWorkspace workspace;
    const Matrix a = RandomMatrix(m, k, &rng);
    const Matrix b = RandomMatrix(k, n, &rng);
    const Matrix bias = RandomMatrix(m, 1, &rng);
    const Matrix mask = RandomMatrix(m, n, &rng);
    Matrix with_bias = a * b;
    with_bias.colwise() += bias.col(0);

    Matrix c(m, n);
    Epilogue relu;
    relu.row_bias = bias.data();
    relu.relu = true;
    Gemm(View(a), View(b), View(&c), /*accumulate=*/false, relu, &workspace);
    EXPECT_LE((c - Matrix(with_bias.cwiseMax(0.0f))).cwiseAbs().maxCoeff(), 1e-4f)
        << m << "x" << n << "x" << k;
    EXPECT_EQ(c.minCoeff(), 0.0f);

    Epilogue masked;
    masked.mask = mask.data();
    Gemm(View(a), View(b), View(&c), /*accumulate=*/false, masked, &workspace);
    const Matrix expected = (mask.array() > 0.0f).select(a * b, 0.0f);
    EXPECT_LE((c - expected).cwiseAbs().maxCoeff(), 1e-4f) << m << "x" << n << "x" << k;
  }
}

TEST_P(GemmTest, EmptySharedDimensionGivesBiasOrKeepsTheAccumulator) {
  GemmWorkspace workspace;
  const Matrix a(3, 0);
  const Matrix b(0, 2);
  Matrix c = Matrix::Constant(3, 2, 7.0f);
  Gemm(View(a), View(b), View(&c), /*accumulate=*/true, {}, &workspace);
  EXPECT_TRUE(c.isApprox(Matrix::Constant(3, 2, 7.0f)));
  const float bias[3] = {1.0f, 2.0f, 3.0f};
  Epilogue epilogue;
  epilogue.row_bias = bias;
  Gemm(View(a), View(b), View(&c), /*accumulate=*/false, epilogue, &workspace);
  EXPECT_EQ(c(2, 1), 3.0f);
  EXPECT_EQ(c(0, 0), 1.0f);
}

// A left operand packed by the caller in the documented layout gives the same product.
TEST_P(GemmTest, PrepackedLeftOperandMatchesEigen) {
  for (const auto& [m, n, k] :
       {std::array<int, 3>{1, 5, 3}, std::array<int, 3>{24, 8, 9}, std::array<int, 3>{49, 64, 576},
        std::array<int, 3>{400, 32, 256}, std::array<int, 3>{30, 13, 300}}) {
    std::mt19937 rng(static_cast<unsigned>(m * 31 + n * 7 + k));
    GemmWorkspace workspace;
    const Matrix a = RandomMatrix(m, k, &rng);
    const Matrix b = RandomMatrix(k, n, &rng);
    const Matrix col_bias = RandomMatrix(n, 1, &rng);
    const int kPanelRows = PackedPanelRows(Precision::kFp32);
    const int panels = (m + kPanelRows - 1) / kPanelRows;
    // Rows past m hold garbage, which must not reach c.
    std::vector<float> packed(static_cast<size_t>(panels) * kPanelRows * k, 1e30f);
    for (int i = 0; i < m; ++i) {
      for (int p = 0; p < k; ++p) {
        const int q = i / kPanelRows;
        packed[(static_cast<size_t>(q) * k + p) * kPanelRows + i % kPanelRows] = a(i, p);
      }
    }
    Epilogue epilogue;
    epilogue.col_bias = col_bias.data();
    epilogue.relu = true;
    Matrix c(m, n);
    GemmPacked(packed.data(), m, k, View(b), View(&c), /*accumulate=*/false, epilogue, &workspace);
    Matrix expected = a * b;
    expected.rowwise() += col_bias.col(0).transpose();
    expected = expected.cwiseMax(0.0f);
    EXPECT_LE((c - expected).cwiseAbs().maxCoeff(), 1e-5f * static_cast<float>(k + 1))
        << m << "x" << n << "x" << k;
  }
}

TEST_P(GemmTest, AddRowSumsAddsTheSumOfEachRowAcrossTheBatch) {
  std::mt19937 rng(5);
  for (int rows : {1, 7, 8, 63, 64, 65, 120, 130}) {
    const Matrix g = RandomMatrix(rows, 37, &rng);
    Matrix out = RandomMatrix(rows, 1, &rng);
    const Matrix expected = out + g.rowwise().sum();
    AddRowSums(g, out.data());
    EXPECT_LE((out - expected).cwiseAbs().maxCoeff(), 1e-4f) << rows << " rows";
  }
}

}  // namespace
}  // namespace rl::nn::internal
