#include "nn/layer_norm.h"

#include <cmath>
#include <random>
#include <stdexcept>

#include <gtest/gtest.h>

#include "tests/nn/gradient_check.h"
#include "tests/nn/layer_gradient_check.h"

namespace rl::nn {
namespace {

TEST(LayerNormTest, NormalisesEachColumnOverItsFeatures) {
  LayerNorm ln(4);
  Matrix x(4, 2);
  x.col(0) << 1, 2, 3, 4;    // Mean 2.5, biased variance 1.25.
  x.col(1) << -1, -1, 1, 1;  // Mean 0, variance 1.
  ln.weight() << 1, 2, 1, 1;
  ln.bias() << 0, 0, 0, 0.5;
  const Matrix& y = ln.Forward(x);
  const double s0 = std::sqrt(1.25 + 1e-5);
  EXPECT_NEAR(y(0, 0), -1.5 / s0, 1e-5);
  EXPECT_NEAR(y(1, 0), 2 * -0.5 / s0, 1e-5);
  EXPECT_NEAR(y(3, 0), 1.5 / s0 + 0.5, 1e-5);
  EXPECT_NEAR(y(2, 1), 1 / std::sqrt(1 + 1e-5), 1e-5);
}

TEST(LayerNormTest, GradientsMatchFiniteDifferences) {
  std::mt19937 rng(4);
  LayerNorm ln(7);
  ln.weight() = RandomMatrix(7, 1, &rng) + Matrix::Constant(7, 1, 1.0f);
  ln.bias() = RandomMatrix(7, 1, &rng);
  const Matrix x = RandomMatrix(7, 5, &rng, 2.0f);
  const Matrix r = RandomMatrix(7, 5, &rng);
  ExpectWeightAndBiasGradientsMatch(&ln, x, r);
}

TEST(LayerNormTest, DescribesItselfAndRejectsZeroFeatures) {
  EXPECT_EQ(LayerNorm(512).Describe(), "layernorm(512)");
  EXPECT_THROW(LayerNorm(0), std::invalid_argument);
}

}  // namespace
}  // namespace rl::nn
