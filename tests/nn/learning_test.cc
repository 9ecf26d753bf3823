// End-to-end sanity check: the library can actually learn a smooth function.
#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "nn/losses.h"
#include "nn/optimizers.h"
#include "nn/sequential.h"

namespace rl::nn {
namespace {

// n points of y = sin(x) evenly spaced on [lo, hi], as a 1 x n input and its targets.
void SinePoints(int n, float lo, float hi, Matrix* x, Vector* y) {
  x->resize(1, n);
  y->resize(n);
  for (int i = 0; i < n; ++i) {
    (*x)(0, i) = lo + (hi - lo) * static_cast<float>(i) / static_cast<float>(n - 1);
    (*y)[i] = std::sin((*x)(0, i));
  }
}

TEST(LearningTest, MlpFitsSineOnMinusThreeToThreeWithAdam) {
  constexpr int kPoints = 128;
  constexpr int kMaxSteps = 5000;
  Matrix x;
  Vector y;
  SinePoints(kPoints, -3.0f, 3.0f, &x, &y);
  std::mt19937 rng(123);
  Sequential net = MakeMlp(1, {32, 32}, 1, &rng);
  Adam adam(net.Params(), /*lr=*/1e-2f);
  Vector pred(kPoints);
  Vector grad;
  pred = net.Forward(x).row(0).transpose();
  const float initial_mse = MseLoss(pred, y, nullptr);
  float mse = initial_mse;
  int step = 0;
  for (; step < kMaxSteps && mse >= 1e-3f; ++step) {
    pred = net.Forward(x).row(0).transpose();
    mse = MseLoss(pred, y, &grad);
    net.ZeroGrad();
    net.Backward(grad.transpose());
    adam.Step();
  }
  EXPECT_GT(initial_mse, 0.1f);
  EXPECT_LT(mse, 1e-3f) << "after " << step << " steps";

  // The fit holds between the training points too.
  Matrix x_test;
  Vector y_test;
  SinePoints(97, -2.97f, 2.97f, &x_test, &y_test);
  const Vector pred_test = net.Forward(x_test).row(0).transpose();
  EXPECT_LT(MseLoss(pred_test, y_test, nullptr), 0.01f);
}

}  // namespace
}  // namespace rl::nn
