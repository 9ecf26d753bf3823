// End-to-end sanity check: the library can actually learn a smooth function.
#include <cmath>
#include <random>
#include <vector>

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

// A batch of 1 x 8 x 8 images: dim noise plus a bright 2 x 2 square, in the left half (label 0)
// or the right half (label 1) at a random row and column.
void SquareImages(int n, std::mt19937* rng, Matrix* x, std::vector<int>* labels) {
  std::uniform_real_distribution<float> noise(0.0f, 0.3f);
  std::uniform_int_distribution<int> coin(0, 1);
  std::uniform_int_distribution<int> row(0, 6);
  std::uniform_int_distribution<int> col(0, 2);
  x->resize(64, n);
  labels->resize(static_cast<size_t>(n));
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < 64; ++i) (*x)(i, j) = noise(*rng);
    const int label = coin(*rng);
    const int y0 = row(*rng);
    const int x0 = col(*rng) + 4 * label;
    for (int dy = 0; dy < 2; ++dy) {
      for (int dx = 0; dx < 2; ++dx) (*x)((y0 + dy) * 8 + x0 + dx, j) = 1.0f;
    }
    (*labels)[static_cast<size_t>(j)] = label;
  }
}

// Softmax cross-entropy over the columns of `logits`; writes d(mean loss)/d(logits) into *grad
// and returns the number of columns whose largest logit is the label.
int CrossEntropyGrad(const Matrix& logits, const std::vector<int>& labels, Matrix* grad) {
  const auto n = logits.cols();
  grad->resize(logits.rows(), n);
  int correct = 0;
  for (Eigen::Index j = 0; j < n; ++j) {
    const Eigen::ArrayXf e = (logits.col(j).array() - logits.col(j).maxCoeff()).exp();
    grad->col(j) = (e / e.sum()).matrix() / static_cast<float>(n);
    (*grad)(labels[static_cast<size_t>(j)], j) -= 1.0f / static_cast<float>(n);
    Eigen::Index best = 0;
    logits.col(j).maxCoeff(&best);
    correct += static_cast<int>(best == labels[static_cast<size_t>(j)]);
  }
  return correct;
}

TEST(LearningTest, SmallConvNetLearnsWhichHalfHoldsTheBrightSquare) {
  constexpr int kBatch = 32;
  constexpr int kSteps = 300;
  std::mt19937 rng(2024);
  Sequential net = BuildFromArchitecture(
      "conv2d(1,4,3,1,1,8,8),relu,conv2d(4,8,3,2,1,8,8),relu,flatten,linear(128,2)", &rng);
  Adam adam(net.Params(), /*lr=*/3e-3f);
  Matrix x;
  Matrix grad;
  std::vector<int> labels;
  for (int step = 0; step < kSteps; ++step) {
    SquareImages(kBatch, &rng, &x, &labels);
    CrossEntropyGrad(net.Forward(x), labels, &grad);
    net.ZeroGrad();
    net.BackwardParams(grad);
    adam.Step();
  }
  // Accuracy on fresh images.
  constexpr int kTest = 1000;
  SquareImages(kTest, &rng, &x, &labels);
  const int correct = CrossEntropyGrad(net.Forward(x), labels, &grad);
  EXPECT_GT(correct, 95 * kTest / 100) << correct << " of " << kTest;
}

}  // namespace
}  // namespace rl::nn
