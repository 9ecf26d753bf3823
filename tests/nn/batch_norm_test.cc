#include "nn/batch_norm.h"

#include <cmath>
#include <memory>
#include <random>
#include <stdexcept>

#include <gtest/gtest.h>

#include "tests/nn/gradient_check.h"
#include "tests/nn/layer_gradient_check.h"

namespace rl::nn {
namespace {

// Two channels of 1 x 2 images, batch 2. Channel 0 holds 1, 3 | 5, 7 (mean 4, biased variance 5,
// unbiased 20/3); channel 1 holds 0, 0 | 2, -2 (mean 0, biased variance 2, unbiased 8/3).
Matrix TinyBatch() {
  Matrix x(4, 2);
  x.col(0) << 1, 3, 0, 0;
  x.col(1) << 5, 7, 2, -2;
  return x;
}

TEST(BatchNorm2dTest, TrainingForwardNormalisesWithBatchStatisticsAndUpdatesRunningOnes) {
  BatchNorm2d bn(2, 1, 2);
  const Matrix& y = bn.Forward(TinyBatch());
  // y = (x - mean) / sqrt(biased var + 1e-5), with weight 1 and bias 0.
  const double s0 = std::sqrt(5.0 + 1e-5);
  const double s1 = std::sqrt(2.0 + 1e-5);
  EXPECT_NEAR(y(0, 0), (1 - 4) / s0, 1e-5);
  EXPECT_NEAR(y(1, 0), (3 - 4) / s0, 1e-5);
  EXPECT_NEAR(y(0, 1), (5 - 4) / s0, 1e-5);
  EXPECT_NEAR(y(1, 1), (7 - 4) / s0, 1e-5);
  EXPECT_NEAR(y(2, 1), 2 / s1, 1e-5);
  EXPECT_NEAR(y(3, 1), -2 / s1, 1e-5);
  // running = 0.9 running + 0.1 batch statistic, with the unbiased variance.
  EXPECT_NEAR(bn.running_mean()(0, 0), 0.1 * 4, 1e-6);
  EXPECT_NEAR(bn.running_mean()(1, 0), 0.0, 1e-6);
  EXPECT_NEAR(bn.running_var()(0, 0), 0.9 * 1 + 0.1 * 20.0 / 3.0, 1e-6);
  EXPECT_NEAR(bn.running_var()(1, 0), 0.9 * 1 + 0.1 * 8.0 / 3.0, 1e-6);
  // A second step moves them again by the same rule.
  bn.Forward(TinyBatch());
  EXPECT_NEAR(bn.running_mean()(0, 0), 0.9 * 0.4 + 0.1 * 4, 1e-6);
  EXPECT_NEAR(bn.running_var()(0, 0), 0.9 * (0.9 + 0.1 * 20.0 / 3.0) + 0.1 * 20.0 / 3.0, 1e-5);
}

TEST(BatchNorm2dTest, EvalModeUsesRunningStatisticsAndLeavesThemAlone) {
  BatchNorm2d bn(2, 1, 2);
  bn.running_mean() << 1.0f, -2.0f;
  bn.running_var() << 4.0f, 0.25f;
  bn.weight() << 2.0f, 3.0f;
  bn.bias() << 0.5f, -1.0f;
  bn.set_training(false);
  const Matrix x = TinyBatch();
  const Matrix& y = bn.Forward(x);
  for (int b = 0; b < 2; ++b) {
    for (int i = 0; i < 2; ++i) {
      EXPECT_NEAR(y(i, b), (x(i, b) - 1.0) / std::sqrt(4.0 + 1e-5) * 2.0 + 0.5, 1e-5);
      EXPECT_NEAR(y(2 + i, b), (x(2 + i, b) + 2.0) / std::sqrt(0.25 + 1e-5) * 3.0 - 1.0, 1e-5);
    }
  }
  EXPECT_EQ(bn.running_mean()(0, 0), 1.0f);
  EXPECT_EQ(bn.running_var()(1, 0), 0.25f);
  // One observation is fine in eval mode.
  EXPECT_NO_THROW(bn.Forward(Matrix(x.col(0))));
}

TEST(BatchNorm2dTest, TrainingModeRejectsASingleValuePerChannel) {
  BatchNorm2d bn(3, 1, 1);
  EXPECT_THROW(bn.Forward(Matrix::Ones(3, 1)), std::invalid_argument);
  EXPECT_NO_THROW(bn.Forward(Matrix::Ones(3, 2)));
}

void CheckBatchNormGradients(bool training) {
  SCOPED_TRACE(training ? "training" : "eval");
  std::mt19937 rng(3);
  BatchNorm2d bn(3, 2, 3);
  bn.weight() = RandomMatrix(3, 1, &rng) + Matrix::Constant(3, 1, 1.5f);
  bn.bias() = RandomMatrix(3, 1, &rng);
  bn.running_mean() = RandomMatrix(3, 1, &rng);
  bn.running_var() = RandomMatrix(3, 1, &rng, 0.5f) + Matrix::Constant(3, 1, 1.0f);
  bn.set_training(training);
  const Matrix x = RandomMatrix(18, 4, &rng, 2.0f);
  const Matrix r = RandomMatrix(18, 4, &rng);
  ExpectWeightAndBiasGradientsMatch(&bn, x, r);
}

TEST(BatchNorm2dTest, TrainingModeGradientsMatchFiniteDifferences) {
  CheckBatchNormGradients(true);
}

TEST(BatchNorm2dTest, EvalModeGradientsMatchFiniteDifferences) { CheckBatchNormGradients(false); }

TEST(BatchNorm2dTest, ExposesAffineParamsAndRunningStatisticsSeparately) {
  BatchNorm2d bn(4, 3, 3);
  ASSERT_EQ(bn.Params().size(), 2u);
  EXPECT_EQ(bn.Params()[0].name, "weight");
  EXPECT_EQ(bn.Params()[1].name, "bias");
  ASSERT_EQ(bn.Buffers().size(), 2u);
  EXPECT_EQ(bn.Buffers()[0].name, "running_mean");
  EXPECT_EQ(bn.Buffers()[1].name, "running_var");
  EXPECT_TRUE(bn.running_mean().isZero());
  EXPECT_TRUE(bn.running_var().isOnes());
  EXPECT_EQ(bn.Describe(), "batchnorm2d(4,3,3)");
  EXPECT_EQ(bn.input_size(), 36);
}

TEST(BatchNorm2dTest, CloneCopiesRunningStatisticsAndMode) {
  BatchNorm2d bn(2, 1, 2);
  bn.Forward(TinyBatch());
  bn.set_training(false);
  const std::unique_ptr<Layer> copy = bn.Clone();
  auto& clone = dynamic_cast<BatchNorm2d&>(*copy);
  EXPECT_EQ(clone.running_mean(), bn.running_mean());
  EXPECT_EQ(clone.running_var(), bn.running_var());
  EXPECT_FALSE(clone.training());
  EXPECT_EQ(Matrix(clone.Forward(TinyBatch())), Matrix(bn.Forward(TinyBatch())));
}

}  // namespace
}  // namespace rl::nn
