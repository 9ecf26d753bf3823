#include "nn/optimizers.h"

#include <array>
#include <cmath>
#include <limits>
#include <memory>
#include <random>
#include <stdexcept>
#include <vector>

#include <gtest/gtest.h>

#include "nn/linear.h"
#include "nn/losses.h"
#include "nn/sequential.h"

namespace rl::nn {
namespace {

// A 2x1 parameter with its gradient, fed known gradients step by step.
struct TwoFloats {
  Matrix value = (Matrix(2, 1) << 1.0f, -2.0f).finished();
  Matrix grad = Matrix::Zero(2, 1);
  std::vector<Param> params() { return {{"p", &value, &grad}}; }
  void SetGrad(float a, float b) { grad << a, b; }
};

// Expected values below come from PyTorch's update rules evaluated in double precision for
// p0 = (1, -2) and gradients g1 = (0.5, -0.1), then g2 = (0.2, 0.3).
TEST(AdamTest, FirstTwoStepsMatchPyTorchUpdateRule) {
  TwoFloats p;
  Adam adam(p.params(), /*lr=*/0.1f);
  p.SetGrad(0.5f, -0.1f);
  adam.Step();
  // Step 1: m_hat = g and v_hat = g^2, so p -= lr * sign(g) (up to eps).
  EXPECT_NEAR(p.value(0), 0.900000002, 1e-6);
  EXPECT_NEAR(p.value(1), -1.90000001, 1e-6);
  p.SetGrad(0.2f, 0.3f);
  adam.Step();
  EXPECT_NEAR(p.value(0), 0.8101424839029282, 1e-5);
  EXPECT_NEAR(p.value(1), -1.9494189911200654, 1e-5);
  EXPECT_EQ(adam.step_count(), 2);
}

struct RmsCase {
  bool centered;
  float momentum;
  std::array<double, 2> step1;
  std::array<double, 2> step2;
};

TEST(RmsPropTest, FirstTwoStepsMatchPyTorchUpdateRule) {
  // The first step does not depend on the momentum: its buffer starts at zero.
  constexpr std::array<double, 2> kPlainStep1 = {0.900000019999996, -1.9000000999999};
  constexpr std::array<double, 2> kCenteredStep1 = {0.899496238676095, -1.8994963194840784};
  const RmsCase cases[] = {
      {false, 0.0f, kPlainStep1, {0.8626998346269039, -1.9949158695451294}},
      {true, 0.0f, kCenteredStep1, {0.8618787112241529, -1.9946045995978066}},
      {false, 0.9f, kPlainStep1, {0.7726998526269003, -1.9049159595450393}},
      {true, 0.9f, kCenteredStep1, {0.7714253260326385, -1.9041512871334771}},
  };
  for (const RmsCase& c : cases) {
    SCOPED_TRACE(::testing::Message() << "centered " << c.centered << " momentum " << c.momentum);
    TwoFloats p;
    RmsProp rms(p.params(), /*lr=*/0.01f, /*alpha=*/0.99f, /*eps=*/1e-8f, c.centered, c.momentum);
    p.SetGrad(0.5f, -0.1f);
    rms.Step();
    EXPECT_NEAR(p.value(0), c.step1[0], 1e-5);
    EXPECT_NEAR(p.value(1), c.step1[1], 1e-5);
    p.SetGrad(0.2f, 0.3f);
    rms.Step();
    EXPECT_NEAR(p.value(0), c.step2[0], 1e-5);
    EXPECT_NEAR(p.value(1), c.step2[1], 1e-5);
  }
}

TEST(OptimizerTest, LearningRateCanBeChangedAndZeroFreezesParameters) {
  TwoFloats p;
  Adam adam(p.params(), 0.1f);
  EXPECT_FLOAT_EQ(adam.learning_rate(), 0.1f);
  adam.set_learning_rate(0.0f);
  EXPECT_EQ(adam.learning_rate(), 0.0f);
  p.SetGrad(1.0f, 1.0f);
  adam.Step();
  EXPECT_FLOAT_EQ(p.value(0), 1.0f);
  EXPECT_FLOAT_EQ(p.value(1), -2.0f);
}

TEST(OptimizerTest, RejectsInvalidHyperparameters) {
  TwoFloats p;
  EXPECT_THROW(Adam(p.params(), -1.0f), std::invalid_argument);
  EXPECT_THROW(Adam(p.params(), 1e-3f, 1.0f), std::invalid_argument);
  EXPECT_THROW(Adam(p.params(), 1e-3f, 0.9f, 1.5f), std::invalid_argument);
  EXPECT_THROW(RmsProp(p.params(), 1e-2f, 1.5f), std::invalid_argument);
  EXPECT_THROW(RmsProp(p.params(), 1e-2f, 0.99f, 1e-8f, false, -0.5f), std::invalid_argument);
}

// Minimises 0.5 * |p - c|^2 (gradient p - c) from p0 = (1, -2) to c = (-3, 4).
template <typename Opt, typename... Args>
Matrix MinimiseQuadratic(int steps, Args... args) {
  TwoFloats p;
  const Matrix c = (Matrix(2, 1) << -3.0f, 4.0f).finished();
  Opt opt(p.params(), args...);
  for (int i = 0; i < steps; ++i) {
    p.grad = p.value - c;
    opt.Step();
  }
  return p.value - c;
}

TEST(AdamTest, MinimisesAQuadratic) {
  EXPECT_LT(MinimiseQuadratic<Adam>(2000, 0.05f).norm(), 1e-2f);
}

TEST(RmsPropTest, MinimisesAQuadraticPlainCenteredAndWithMomentum) {
  EXPECT_LT(MinimiseQuadratic<RmsProp>(3000, 0.01f).norm(), 5e-2f);
  EXPECT_LT(MinimiseQuadratic<RmsProp>(3000, 0.01f, 0.99f, 1e-8f, true).norm(), 5e-2f);
  EXPECT_LT(MinimiseQuadratic<RmsProp>(3000, 0.001f, 0.99f, 1e-8f, false, 0.9f).norm(), 5e-2f);
}

// Fits y = 2x - 1 with one Linear unit and MSE; returns (w, b).
template <typename Opt>
std::pair<float, float> FitLine(float lr) {
  std::mt19937 rng(1);
  Linear layer(1, 1, &rng);
  Matrix x(1, 32);
  Vector y(32);
  for (int i = 0; i < 32; ++i) {
    x(0, i) = -1.0f + 2.0f * static_cast<float>(i) / 31.0f;
    y[i] = 2.0f * x(0, i) - 1.0f;
  }
  Opt opt(layer.Params(), lr);
  Vector grad;
  for (int step = 0; step < 2000; ++step) {
    const Vector pred = layer.Forward(x).row(0).transpose();
    MseLoss(pred, y, &grad);
    for (Param& p : layer.Params()) p.grad->setZero();
    layer.Backward(grad.transpose());
    opt.Step();
  }
  return {layer.weight()(0, 0), layer.bias()(0, 0)};
}

TEST(AdamTest, FitsALinearRegression) {
  const auto [w, b] = FitLine<Adam>(0.05f);
  EXPECT_NEAR(w, 2.0f, 1e-2f);
  EXPECT_NEAR(b, -1.0f, 1e-2f);
}

TEST(RmsPropTest, FitsALinearRegression) {
  const auto [w, b] = FitLine<RmsProp>(0.005f);
  EXPECT_NEAR(w, 2.0f, 5e-2f);
  EXPECT_NEAR(b, -1.0f, 5e-2f);
}

TEST(ClipGradNormTest, ScalesGradientsDownToMaxNormAndReturnsTheOriginalNorm) {
  Matrix v1 = Matrix::Zero(1, 1);
  Matrix g1 = (Matrix(1, 1) << 3.0f).finished();
  Matrix v2 = Matrix::Zero(1, 1);
  Matrix g2 = (Matrix(1, 1) << -4.0f).finished();
  const std::vector<Param> params = {{"a", &v1, &g1}, {"b", &v2, &g2}};
  EXPECT_FLOAT_EQ(ClipGradNorm(params, 1.0f), 5.0f);
  EXPECT_NEAR(g1(0), 0.6f, 1e-6f);
  EXPECT_NEAR(g2(0), -0.8f, 1e-6f);
}

TEST(ClipGradNormTest, LeavesSmallGradientsAlone) {
  Matrix v = Matrix::Zero(2, 1);
  Matrix g = (Matrix(2, 1) << 3.0f, 4.0f).finished();
  const std::vector<Param> params = {{"a", &v, &g}};
  EXPECT_FLOAT_EQ(ClipGradNorm(params, 10.0f), 5.0f);
  EXPECT_EQ(g(0), 3.0f);
  EXPECT_EQ(g(1), 4.0f);
}

TEST(ClipGradNormTest, ReportsANonFiniteNormWithoutTouchingGradients) {
  Matrix v = Matrix::Zero(2, 1);
  Matrix g = (Matrix(2, 1) << std::numeric_limits<float>::quiet_NaN(), 4.0f).finished();
  const std::vector<Param> params = {{"a", &v, &g}};
  EXPECT_TRUE(std::isnan(ClipGradNorm(params, 1.0f)));
  EXPECT_EQ(g(1), 4.0f);
}

// Steps run over tensors in chunks; every element of a tensor spanning several chunks (and a
// ragged last one) follows the update rule.
TEST(OptimizerTest, LargeTensorsAreUpdatedElementByElement) {
  std::mt19937 rng(12);
  std::uniform_real_distribution<float> dist(-1.0f, 1.0f);
  Matrix value(50, 51);
  Matrix grad(50, 51);
  for (Eigen::Index i = 0; i < value.size(); ++i) {
    value.data()[i] = dist(rng);
    grad.data()[i] = dist(rng);
  }
  const Matrix start = value;
  {
    Adam adam({{"p", &value, &grad}}, /*lr=*/0.01f);
    adam.Step();
    // First step: m_hat = g, v_hat = g^2.
    for (Eigen::Index i = 0; i < value.size(); ++i) {
      const double g = grad.data()[i];
      EXPECT_NEAR(value.data()[i], start.data()[i] - 0.01 * g / (std::abs(g) + 1e-8), 1e-6) << i;
    }
  }
  value = start;
  {
    RmsProp rms({{"p", &value, &grad}}, /*lr=*/0.01f, /*alpha=*/0.95f, /*eps=*/0.01f,
                /*centered=*/true);
    rms.Step();
    // s = 0.05 g^2, a = 0.05 g: denominator sqrt(s - a^2) + eps.
    for (Eigen::Index i = 0; i < value.size(); ++i) {
      const double g = grad.data()[i];
      const double denom = std::sqrt(0.05 * g * g - 0.0025 * g * g) + 0.01;
      EXPECT_NEAR(value.data()[i], start.data()[i] - 0.01 * g / denom, 1e-5) << i;
    }
  }
}

// DeepMind's centred RMSProp (lr 2.5e-4, alpha 0.95, eps 0.01) on a small convolutional network:
// the loss on a fixed batch goes down and every parameter tensor with a gradient moves.
TEST(RmsPropTest, CenteredRmsPropTrainsAConvNet) {
  std::mt19937 rng(13);
  Sequential net = BuildFromArchitecture(
      "conv2d(2,4,3,2,0,9,9),batchnorm2d(4,4,4),relu,conv2d(4,8,2,1,0,4,4),relu,flatten,"
      "linear(72,3)",
      &rng);
  const std::vector<Param> params = net.Params();
  RmsProp rms(params, 2.5e-4f, 0.95f, 0.01f, /*centered=*/true);
  std::uniform_real_distribution<float> dist(0.0f, 1.0f);
  Matrix x(net.InputSize(), 16);
  for (Eigen::Index i = 0; i < x.size(); ++i) x.data()[i] = dist(rng);
  Vector target(16);
  for (int j = 0; j < 16; ++j) target[j] = static_cast<float>(j % 3) - 1.0f;
  std::vector<Matrix> before;
  for (const Param& p : params) before.push_back(*p.value);

  Vector pred(16);
  Vector grad;
  Matrix grad_q(3, 16);
  auto loss = [&](bool backward) {
    const Matrix& q = net.Forward(x);
    for (int j = 0; j < 16; ++j) pred[j] = q(j % 3, j);
    const float l = MseLoss(pred, target, &grad);
    if (backward) {
      grad_q.setZero();
      for (int j = 0; j < 16; ++j) grad_q(j % 3, j) = grad[j];
      net.ZeroGrad();
      net.BackwardParams(grad_q);
    }
    return l;
  };
  const float initial = loss(false);
  for (int step = 0; step < 200; ++step) {
    loss(true);
    rms.Step();
  }
  EXPECT_LT(loss(false), 0.5f * initial);
  for (size_t i = 0; i < params.size(); ++i) {
    const float moved = (*params[i].value - before[i]).cwiseAbs().maxCoeff();
    if (params[i].name == "0.bias") {
      // Batch normalisation in training mode subtracts the mean of each channel, so the bias of
      // the convolution before it has no gradient.
      EXPECT_LT(moved, 1e-6f) << params[i].name;
    } else {
      EXPECT_GT(moved, 1e-4f) << params[i].name;
    }
  }
}

// A copy of an optimizer's state (and of the parameters) continues exactly as the original.
TEST(OptimizerStateTest, RestoredStateContinuesBitForBit) {
  for (int kind = 0; kind < 2; ++kind) {
    TwoFloats a, b;
    std::unique_ptr<Optimizer> oa, ob;
    if (kind == 0) {
      oa = std::make_unique<Adam>(a.params(), 0.1f);
      ob = std::make_unique<Adam>(b.params(), 0.1f);
    } else {
      oa = std::make_unique<RmsProp>(a.params(), 0.1f, 0.9f, 1e-8f, true, 0.5f);
      ob = std::make_unique<RmsProp>(b.params(), 0.1f, 0.9f, 1e-8f, true, 0.5f);
    }
    a.SetGrad(0.5f, -0.1f);
    oa->Step();
    a.SetGrad(0.2f, 0.3f);
    oa->Step();
    std::vector<float> state;
    int64_t steps = -1;
    oa->GetState(&state, &steps);
    EXPECT_EQ(state.size(), kind == 0 ? 4U : 6U);  // Adam: m, v; centred RMSprop with momentum: 3
    EXPECT_EQ(steps, kind == 0 ? 2 : 0);
    ob->SetState(state, steps);
    b.value = a.value;
    a.SetGrad(-0.4f, 0.7f);
    b.SetGrad(-0.4f, 0.7f);
    oa->Step();
    ob->Step();
    EXPECT_EQ(a.value(0), b.value(0));
    EXPECT_EQ(a.value(1), b.value(1));
    // A state of another size is refused.
    state.push_back(1.0f);
    EXPECT_THROW(ob->SetState(state, steps), std::invalid_argument);
    state.pop_back();
    EXPECT_THROW(ob->SetState(state, -1), std::invalid_argument);
  }
}

}  // namespace
}  // namespace rl::nn
