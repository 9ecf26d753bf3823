#include "nn/activations.h"

#include <random>

#include <gtest/gtest.h>

#include "tests/nn/gradient_check.h"

namespace rl::nn {
namespace {

// Inputs in +-[0.1, 2], away from ReLU's kink at 0 relative to the finite-difference step.
Matrix AwayFromZero(int rows, int cols, std::mt19937* rng) {
  Matrix x = RandomMatrix(rows, cols, rng, 2.0f);
  for (Eigen::Index i = 0; i < x.size(); ++i) {
    float& v = x.data()[i];
    if (std::abs(v) < 0.1f) v = v < 0 ? -0.1f : 0.1f;
  }
  return x;
}

template <typename L>
void CheckGradient() {
  std::mt19937 rng(2);
  L layer;
  Matrix x = AwayFromZero(6, 5, &rng);
  const Matrix r = RandomMatrix(6, 5, &rng);
  auto loss = [&] { return Dot(r, layer.Forward(x)); };
  layer.Forward(x);
  const Matrix dx = layer.Backward(r);
  ExpectGradientsClose(dx, NumericalGradient(loss, &x), layer.Describe());
}

TEST(ReLUTest, GradientMatchesFiniteDifferences) { CheckGradient<ReLU>(); }

TEST(TanhTest, GradientMatchesFiniteDifferences) { CheckGradient<Tanh>(); }

TEST(ReLUTest, ZeroesNegativesAndTheirGradients) {
  ReLU relu;
  Matrix x(1, 4);
  x << -1.0f, 0.0f, 0.5f, 3.0f;
  Matrix y(1, 4);
  y << 0.0f, 0.0f, 0.5f, 3.0f;
  EXPECT_EQ(relu.Forward(x), y);
  Matrix dx(1, 4);
  dx << 0.0f, 0.0f, 1.0f, 1.0f;
  EXPECT_EQ(relu.Backward(Matrix::Ones(1, 4)), dx);
}

TEST(TanhTest, ForwardMatchesStdTanh) {
  std::mt19937 rng(4);
  Tanh tanh_layer;
  const Matrix x = RandomMatrix(3, 7, &rng, 4.0f);
  const Matrix& y = tanh_layer.Forward(x);
  for (Eigen::Index i = 0; i < x.size(); ++i) {
    EXPECT_NEAR(y.data()[i], std::tanh(x.data()[i]), 1e-6f);
  }
}

TEST(ActivationTest, DescribeAndCloneKeepTheKind) {
  ReLU relu;
  Tanh tanh_layer;
  EXPECT_EQ(relu.Describe(), "relu");
  EXPECT_EQ(tanh_layer.Describe(), "tanh");
  EXPECT_EQ(relu.Clone()->Describe(), "relu");
  EXPECT_EQ(tanh_layer.Clone()->Describe(), "tanh");
  EXPECT_TRUE(relu.Params().empty());
}

}  // namespace
}  // namespace rl::nn
