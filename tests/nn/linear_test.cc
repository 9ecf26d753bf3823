#include "nn/linear.h"

#include <cmath>
#include <random>
#include <stdexcept>

#include <gtest/gtest.h>

#include "tests/nn/gradient_check.h"

namespace rl::nn {
namespace {

// Checks input, weight and bias gradients of a Linear layer against finite differences of
// loss = sum(r .* layer(x)).
void CheckLinearGradients(int in, int out, int batch) {
  std::mt19937 rng(7);
  Linear layer(in, out, &rng);
  Matrix x = RandomMatrix(in, batch, &rng);
  const Matrix r = RandomMatrix(out, batch, &rng);
  auto loss = [&] { return Dot(r, layer.Forward(x)); };

  layer.Forward(x);
  const Matrix dx = layer.Backward(r);
  const Matrix dw = layer.weight_grad();
  const Matrix db = layer.bias_grad();

  ExpectGradientsClose(dx, NumericalGradient(loss, &x), "input");
  ExpectGradientsClose(dw, NumericalGradient(loss, &layer.weight()), "weight");
  ExpectGradientsClose(db, NumericalGradient(loss, &layer.bias()), "bias");
}

TEST(LinearTest, GradientsMatchFiniteDifferencesForSmallBatches) { CheckLinearGradients(5, 3, 4); }

TEST(LinearTest, GradientsMatchFiniteDifferencesOnTheBatchedKernelPath) {
  // Large enough that every product goes through the packed kernel, with ragged tails.
  CheckLinearGradients(41, 30, 21);
}

TEST(LinearTest, ForwardComputesWeightTimesInputPlusBias) {
  Matrix w(2, 3);
  w << 1, 2, 3, -1, 0, 4;
  Matrix b(2, 1);
  b << 0.5f, -1;
  Linear layer(w, b);
  Matrix x(3, 2);
  x << 1, 0, 1, 1, 2, -1;
  Matrix expected(2, 2);
  expected << 1 + 2 + 6 + 0.5f, 0 + 2 - 3 + 0.5f, -1 + 0 + 8 - 1, 0 + 0 - 4 - 1;
  EXPECT_TRUE(layer.Forward(x).isApprox(expected));
}

TEST(LinearTest, BackwardAccumulatesParameterGradients) {
  std::mt19937 rng(3);
  Linear layer(6, 4, &rng);
  const Matrix x = RandomMatrix(6, 9, &rng);
  const Matrix r = RandomMatrix(4, 9, &rng);
  layer.Forward(x);
  layer.Backward(r);
  const Matrix once_w = layer.weight_grad();
  const Matrix once_b = layer.bias_grad();
  layer.Backward(r);
  EXPECT_TRUE(layer.weight_grad().isApprox(2 * once_w));
  EXPECT_TRUE(layer.bias_grad().isApprox(2 * once_b));
}

TEST(LinearTest, InitialisesWithinPyTorchDefaultBounds) {
  std::mt19937 rng(11);
  Linear layer(100, 50, &rng);
  const float bound = 1.0f / std::sqrt(100.0f);
  EXPECT_LE(layer.weight().cwiseAbs().maxCoeff(), bound);
  EXPECT_LE(layer.bias().cwiseAbs().maxCoeff(), bound);
  // The whole range is used and centred: not a constant or a narrower distribution.
  EXPECT_GT(layer.weight().maxCoeff(), 0.95f * bound);
  EXPECT_LT(layer.weight().minCoeff(), -0.95f * bound);
  EXPECT_NEAR(layer.weight().mean(), 0.0f, 0.05f * bound);
  // U(-a, a) has variance a^2 / 3.
  const float var = layer.weight().array().square().mean();
  EXPECT_NEAR(var, bound * bound / 3.0f, 0.05f * bound * bound);
  EXPECT_TRUE(layer.weight_grad().isZero());
  EXPECT_TRUE(layer.bias_grad().isZero());
}

TEST(LinearTest, SameSeedGivesSameParametersAndDifferentSeedsDiffer) {
  std::mt19937 rng_a(5);
  std::mt19937 rng_b(5);
  std::mt19937 rng_c(6);
  Linear a(8, 4, &rng_a);
  Linear b(8, 4, &rng_b);
  Linear c(8, 4, &rng_c);
  EXPECT_EQ(a.weight(), b.weight());
  EXPECT_EQ(a.bias(), b.bias());
  EXPECT_NE(a.weight(), c.weight());
}

TEST(LinearTest, DescribeAndCloneCopyParametersButNotGradients) {
  std::mt19937 rng(1);
  Linear layer(4, 120, &rng);
  EXPECT_EQ(layer.Describe(), "linear(4,120)");
  const Matrix x = RandomMatrix(4, 3, &rng);
  layer.Forward(x);
  layer.Backward(Matrix::Ones(120, 3));
  auto clone = layer.Clone();
  auto* copy = dynamic_cast<Linear*>(clone.get());
  ASSERT_NE(copy, nullptr);
  EXPECT_EQ(copy->weight(), layer.weight());
  EXPECT_EQ(copy->bias(), layer.bias());
  EXPECT_TRUE(copy->weight_grad().isZero());
  copy->weight()(0, 0) += 1.0f;
  EXPECT_NE(copy->weight()(0, 0), layer.weight()(0, 0));
}

TEST(LinearTest, RejectsNonPositiveSizes) {
  std::mt19937 rng(1);
  EXPECT_THROW(Linear(0, 3, &rng), std::invalid_argument);
  EXPECT_THROW(Linear(3, -1, &rng), std::invalid_argument);
  EXPECT_THROW(Linear(Matrix::Zero(3, 2), Matrix::Zero(2, 1)), std::invalid_argument);
}

TEST(LinearTest, AbortsOnAnInputOfTheWrongSize) {
  std::mt19937 rng(1);
  Linear layer(4, 2, &rng);
  EXPECT_DEATH(layer.Forward(Matrix::Zero(5, 1)), "linear\\(4,2\\) got an input with 5 rows");
}

}  // namespace
}  // namespace rl::nn
