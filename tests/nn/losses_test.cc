#include "nn/losses.h"

#include <random>

#include <gtest/gtest.h>

namespace rl::nn {
namespace {

Vector Vec(std::initializer_list<float> values) {
  Vector v(static_cast<Eigen::Index>(values.size()));
  Eigen::Index i = 0;
  for (float x : values) v[i++] = x;
  return v;
}

TEST(HuberLossTest, MatchesHandComputedValuesInBothRegions) {
  // Errors 0.5 (quadratic: 0.5 * 0.25 = 0.125) and -3 (linear: 3 - 0.5 = 2.5).
  const Vector pred = Vec({1.5f, -1.0f});
  const Vector target = Vec({1.0f, 2.0f});
  Vector grad;
  EXPECT_FLOAT_EQ(HuberLoss(pred, target, &grad), (0.125f + 2.5f) / 2);
  ASSERT_EQ(grad.size(), 2);
  // d/dpred of the mean: e / n in the quadratic region, sign(e) * delta / n beyond it.
  EXPECT_FLOAT_EQ(grad[0], 0.5f / 2);
  EXPECT_FLOAT_EQ(grad[1], -1.0f / 2);
}

TEST(HuberLossTest, HonoursDelta) {
  // |e| = 3 with delta 2: 2 * (3 - 1) = 4; |e| = 1: 0.5.
  const Vector pred = Vec({3.0f, 1.0f});
  const Vector target = Vec({0.0f, 0.0f});
  Vector grad;
  EXPECT_FLOAT_EQ(HuberLoss(pred, target, &grad, 2.0f), (4.0f + 0.5f) / 2);
  EXPECT_FLOAT_EQ(grad[0], 2.0f / 2);
  EXPECT_FLOAT_EQ(grad[1], 1.0f / 2);
}

TEST(HuberLossTest, WeightsScaleEachElement) {
  const Vector pred = Vec({1.5f, -1.0f, 0.0f});
  const Vector target = Vec({1.0f, 2.0f, 0.2f});
  const Vector weights = Vec({2.0f, 0.5f, 1.0f});
  Vector grad;
  const float loss = HuberLoss(pred, target, &grad, 1.0f, &weights);
  EXPECT_FLOAT_EQ(loss, (2.0f * 0.125f + 0.5f * 2.5f + 0.5f * 0.04f) / 3);
  EXPECT_FLOAT_EQ(grad[0], 2.0f * 0.5f / 3);
  EXPECT_FLOAT_EQ(grad[1], 0.5f * -1.0f / 3);
  EXPECT_FLOAT_EQ(grad[2], -0.2f / 3);
}

TEST(MseLossTest, MatchesHandComputedValues) {
  const Vector pred = Vec({1.5f, -1.0f});
  const Vector target = Vec({1.0f, 2.0f});
  Vector grad;
  EXPECT_FLOAT_EQ(MseLoss(pred, target, &grad), (0.25f + 9.0f) / 2);
  EXPECT_FLOAT_EQ(grad[0], 2 * 0.5f / 2);
  EXPECT_FLOAT_EQ(grad[1], 2 * -3.0f / 2);
}

TEST(MseLossTest, WeightsScaleEachElement) {
  const Vector pred = Vec({1.5f, -1.0f});
  const Vector target = Vec({1.0f, 2.0f});
  const Vector weights = Vec({4.0f, 0.0f});
  Vector grad;
  EXPECT_FLOAT_EQ(MseLoss(pred, target, &grad, &weights), 4.0f * 0.25f / 2);
  EXPECT_FLOAT_EQ(grad[0], 4.0f * 2 * 0.5f / 2);
  EXPECT_FLOAT_EQ(grad[1], 0.0f);
}

TEST(LossTest, GradientsMatchFiniteDifferences) {
  std::mt19937 rng(9);
  std::uniform_real_distribution<float> dist(-3.0f, 3.0f);
  Vector pred(16);
  Vector target(16);
  Vector weights(16);
  for (int i = 0; i < 16; ++i) {
    pred[i] = dist(rng);
    target[i] = dist(rng);
    weights[i] = 0.5f + 0.25f * dist(rng);
  }
  for (int which = 0; which < 2; ++which) {
    auto loss = [&](Vector* grad) {
      return which == 0 ? HuberLoss(pred, target, grad, 1.0f, &weights)
                        : MseLoss(pred, target, grad, &weights);
    };
    Vector grad;
    loss(&grad);
    const float eps = 1e-3f;
    for (int i = 0; i < 16; ++i) {
      const float saved = pred[i];
      pred[i] = saved + eps;
      const double plus = loss(nullptr);
      pred[i] = saved - eps;
      const double minus = loss(nullptr);
      pred[i] = saved;
      EXPECT_NEAR(grad[i], (plus - minus) / (2 * eps), 1e-3) << "loss " << which << " i " << i;
    }
  }
}

TEST(LossTest, EmptyBatchHasZeroLoss) {
  Vector grad(3);
  EXPECT_EQ(HuberLoss(Vector(), Vector(), &grad), 0.0f);
  EXPECT_EQ(grad.size(), 0);
  EXPECT_EQ(MseLoss(Vector(), Vector(), nullptr), 0.0f);
}

TEST(LossTest, AbortsOnMismatchedSizes) {
  EXPECT_DEATH(MseLoss(Vector(3), Vector(2), nullptr), "3 predictions but 2 targets");
}

}  // namespace
}  // namespace rl::nn
