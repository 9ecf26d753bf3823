// The layers TD3 and the TD3 CarRacing networks add to nn: Bounded (tanh scaled to per-dimension
// bounds), Pool2d (max and average), ActionValueNet (critic over [features; action]) with its
// action gradient, Polyak averaging, separate optimizers per parameter group, and the presets.
#include <cmath>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "nn/action_value_net.h"
#include "nn/activations.h"
#include "nn/optimizers.h"
#include "nn/pool2d.h"
#include "nn/presets.h"
#include "nn/sequential.h"
#include "tests/nn/gradient_check.h"

namespace rl::nn {
namespace {

TEST(BoundedTest, MapsTanhOntoEachDimensionsBounds) {
  Bounded b({-1.0f, 0.0f, 0.0f}, {1.0f, 1.0f, 2.0f});
  Matrix x(3, 2);
  x << 0.0f, 100.0f,  //
      0.0f, -100.0f,  //
      0.5f, 1.0f;
  const Matrix& y = b.Forward(x);
  EXPECT_FLOAT_EQ(y(0, 0), 0.0f);
  EXPECT_FLOAT_EQ(y(0, 1), 1.0f);
  EXPECT_FLOAT_EQ(y(1, 0), 0.5f);
  EXPECT_FLOAT_EQ(y(1, 1), 0.0f);
  EXPECT_FLOAT_EQ(y(2, 0), 1.0f + std::tanh(0.5f));
  EXPECT_FLOAT_EQ(y(2, 1), 1.0f + std::tanh(1.0f));
  EXPECT_THROW(Bounded({0.0f}, {0.0f}), std::invalid_argument);
  EXPECT_THROW(Bounded({0.0f, 1.0f}, {1.0f}), std::invalid_argument);
  EXPECT_THROW(Bounded({std::nanf("")}, {1.0f}), std::invalid_argument);
}

TEST(BoundedTest, GradientMatchesFiniteDifferencesAndTheStringRoundTrips) {
  Bounded b({-1.0f, 0.0f}, {1.0f, 0.3f});
  std::mt19937 rng(1);
  Matrix x = RandomMatrix(2, 5, &rng, 2.0f);
  const Matrix r = RandomMatrix(2, 5, &rng);
  b.Forward(x);
  const Matrix analytic = b.Backward(r);
  const Matrix numeric = NumericalGradient([&] { return Dot(r, b.Forward(x)); }, &x);
  ExpectGradientsClose(analytic, numeric, "bounded input gradient");
  Sequential net = BuildFromArchitecture("linear(3,2),bounded(2,-1,1,0,0.300000012)", &rng);
  EXPECT_EQ(BuildFromArchitecture(net.Architecture(), &rng).Architecture(), net.Architecture());
  EXPECT_THROW(BuildFromArchitecture("linear(3,2),bounded(2,-1,1,0)", &rng), std::invalid_argument);
  EXPECT_THROW(BuildFromArchitecture("linear(3,2),bounded(2,-1,1,x,2)", &rng),
               std::invalid_argument);
}

// A bounds count above INT_MAX / 2 is refused with its count, without a signed overflow (the
// string comes from checkpoints and weight messages). Found by fuzz/fuzz_checkpoint.
TEST(BoundedTest, RefusesAHugeBoundsCount) {
  std::mt19937 rng(1);
  try {
    BuildFromArchitecture("linear(3,2),bounded(1924571982)", &rng);
    ADD_FAILURE() << "no error";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("needs 3849143964 bounds"), std::string::npos) << e.what();
  }
}

TEST(Pool2dTest, PoolsWindowsOfKByKWithFloorMode) {
  // One channel, 5 x 5 (the last row and column fall outside the 2 x 2 windows).
  Pool2d max(Pool2d::Mode::kMax, 1, 2, 5, 5);
  Pool2d avg(Pool2d::Mode::kAverage, 1, 2, 5, 5);
  EXPECT_EQ(max.output_shape(), (ImageShape{.channels = 1, .height = 2, .width = 2}));
  Matrix x(25, 1);
  for (int i = 0; i < 25; ++i) x(i, 0) = static_cast<float>((i * 7) % 11);
  const Matrix& m = max.Forward(x);
  const Matrix a = avg.Forward(x);
  // Window (0, 0): pixels 0, 1, 5, 6 -> 0, 7, 2, 9.
  EXPECT_EQ(m(0, 0), 9.0f);
  EXPECT_FLOAT_EQ(a(0, 0), (0 + 7 + 2 + 9) / 4.0f);
  // Window (1, 1): pixels 12, 13, 17, 18 -> 7, 3, 9, 5.
  EXPECT_EQ(m(3, 0), 9.0f);
  EXPECT_FLOAT_EQ(a(3, 0), (7 + 3 + 9 + 5) / 4.0f);
  EXPECT_THROW(Pool2d(Pool2d::Mode::kMax, 1, 3, 2, 2), std::invalid_argument);
}

// Max pooling against a direct loop, with many equal values: the first maximum of each window
// (row by row) is the one kept and the one the gradient goes to, for the 2 x 2 windows (computed
// a row at a time) and for others.
TEST(Pool2dTest, MaxPoolingKeepsTheFirstOfEqualMaxima) {
  std::mt19937 rng(4);
  std::uniform_int_distribution<int> level(0, 3);
  for (const int kernel : {2, 3}) {
    Pool2d pool(Pool2d::Mode::kMax, 3, kernel, 41, 23);
    const ImageShape out = pool.output_shape();
    Matrix x(pool.input_size(), 2);
    for (Eigen::Index i = 0; i < x.size(); ++i) x.data()[i] = static_cast<float>(level(rng));
    const Matrix y = pool.Forward(x);
    const Matrix g = Matrix::Ones(pool.output_size(), 2);
    const Matrix dx = pool.Backward(g);
    Matrix want_dx = Matrix::Zero(x.rows(), 2);
    for (int n = 0; n < 2; ++n) {
      for (int c = 0; c < 3; ++c) {
        for (int oy = 0; oy < out.height; ++oy) {
          for (int ox = 0; ox < out.width; ++ox) {
            int best = -1;
            for (int ky = 0; ky < kernel; ++ky) {
              for (int kx = 0; kx < kernel; ++kx) {
                const int i = (c * 41 + oy * kernel + ky) * 23 + ox * kernel + kx;
                if (best < 0 || x(i, n) > x(best, n)) best = i;
              }
            }
            ASSERT_EQ(y((c * out.height + oy) * out.width + ox, n), x(best, n));
            want_dx(best, n) += 1.0f;
          }
        }
      }
    }
    EXPECT_EQ((dx - want_dx).cwiseAbs().maxCoeff(), 0.0f) << "kernel " << kernel;
  }
}

TEST(Pool2dTest, GradientsMatchFiniteDifferences) {
  std::mt19937 rng(2);
  for (Pool2d::Mode mode : {Pool2d::Mode::kMax, Pool2d::Mode::kAverage}) {
    Pool2d pool(mode, 2, 2, 5, 4);
    Matrix x = RandomMatrix(40, 3, &rng);
    const Matrix r = RandomMatrix(pool.output_size(), 3, &rng);
    pool.Forward(x);
    const Matrix analytic = pool.Backward(r);
    const Matrix numeric = NumericalGradient([&] { return Dot(r, pool.Forward(x)); }, &x);
    ExpectGradientsClose(analytic, numeric, mode == Pool2d::Mode::kMax ? "max" : "avg");
  }
}

// The TD3 article's critic shape in small: an obs branch, an action branch and a head.
ActionValueNet SmallCritic(std::mt19937* rng) {
  return BuildActionValueNet("linear(3,4),relu|linear(2,2),relu|linear(6,5),relu,linear(5,1)", 3, 2,
                             rng);
}

TEST(ActionValueNetTest, GradientsWithRespectToObservationActionAndParameters) {
  std::mt19937 rng(3);
  for (const char* arch : {"linear(3,4),relu|linear(2,2),relu|linear(6,5),relu,linear(5,1)",
                           "||linear(5,4),tanh,linear(4,1)"}) {
    ActionValueNet q = BuildActionValueNet(arch, 3, 2, &rng);
    Matrix obs = RandomMatrix(3, 4, &rng);
    Matrix act = RandomMatrix(2, 4, &rng);
    const Matrix r = RandomMatrix(1, 4, &rng);
    const auto loss = [&] { return Dot(r, q.Forward(obs, act)); };
    q.ZeroGrad();
    q.Forward(obs, act);
    q.Backward(r);
    const Matrix grad_obs = q.grad_obs();
    const Matrix grad_act = q.grad_action();
    ExpectGradientsClose(grad_act, NumericalGradient(loss, &act), std::string(arch) + " dQ/da");
    ExpectGradientsClose(grad_obs, NumericalGradient(loss, &obs), std::string(arch) + " dQ/ds");
    for (Param& p : q.Params()) {
      const Matrix analytic = *p.grad;
      ExpectGradientsClose(analytic, NumericalGradient(loss, p.value), p.name);
    }
    // BackwardParams gives the same action gradient and parameter gradients.
    std::vector<Matrix> grads;
    for (Param& p : q.Params()) grads.push_back(*p.grad);
    q.ZeroGrad();
    q.Forward(obs, act);
    q.BackwardParams(r);
    EXPECT_TRUE(q.grad_action().isApprox(grad_act));
    size_t k = 0;
    for (Param& p : q.Params()) EXPECT_TRUE(p.grad->isApprox(grads[k++])) << p.name;
  }
}

TEST(ActionValueNetTest, CopiesRoundTripsAndPolyakAveraging) {
  std::mt19937 rng(4);
  ActionValueNet a = SmallCritic(&rng);
  ActionValueNet b = SmallCritic(&rng);
  EXPECT_EQ(a.Architecture(), "linear(3,4),relu|linear(2,2),relu|linear(6,5),relu,linear(5,1)");
  EXPECT_EQ(a.Params().front().name, "obs.0.weight");
  EXPECT_EQ(a.Params().back().name, "head.2.bias");
  std::vector<float> fa, fb, fc;
  a.GetFlat(&fa);
  b.GetFlat(&fb);
  ASSERT_NE(fa, fb);
  ActionValueNet c = a;  // a deep copy
  c.SoftUpdateFrom(b, 0.25f);
  c.GetFlat(&fc);
  ASSERT_EQ(fc.size(), fa.size());
  for (size_t k = 0; k < fc.size(); ++k) EXPECT_FLOAT_EQ(fc[k], 0.25f * fb[k] + 0.75f * fa[k]);
  std::vector<float> again;
  a.GetFlat(&again);
  EXPECT_EQ(again, fa);  // the copy did not share parameters
  c.CopyParamsFrom(b);
  c.GetFlat(&fc);
  EXPECT_EQ(fc, fb);
  c.SetFlat(fa.data(), fa.size());
  c.GetFlat(&fc);
  EXPECT_EQ(fc, fa);
  EXPECT_THROW(c.SetFlat(fa.data(), fa.size() - 1), std::invalid_argument);
  EXPECT_THROW(BuildActionValueNet("linear(3,4)|linear(6,1)", 3, 2, &rng), std::invalid_argument);
  EXPECT_THROW(BuildActionValueNet("||linear(4,1)", 3, 2, &rng), std::invalid_argument);
  EXPECT_THROW(BuildActionValueNet("||linear(5,2)", 3, 2, &rng), std::invalid_argument);
}

TEST(SequentialTest, PolyakAveragingMovesEachParameterByTau) {
  std::mt19937 rng(5);
  Sequential a = MakeMlp(3, {4}, 2, &rng);
  Sequential b = MakeMlp(3, {4}, 2, &rng);
  std::vector<float> fa, fb, after;
  a.GetFlat(&fa);
  b.GetFlat(&fb);
  a.SoftUpdateFrom(b, 0.005f);
  a.GetFlat(&after);
  for (size_t k = 0; k < after.size(); ++k) {
    EXPECT_FLOAT_EQ(after[k], 0.005f * fb[k] + 0.995f * fa[k]);
  }
}

// Two parameter groups (actor, critic) with their own Adam and learning rate: each step moves its
// own group only, by its own step size (Adam's first step is lr * sign(gradient)).
TEST(OptimizersTest, ParameterGroupsHaveTheirOwnOptimizers) {
  std::mt19937 rng(6);
  Sequential actor = MakeMlp(2, {3}, 1, &rng);
  ActionValueNet critic = BuildActionValueNet("||linear(3,3),relu,linear(3,1)", 2, 1, &rng);
  Adam actor_opt(actor.Params(), 1e-2f);
  Adam critic_opt(critic.Params(), 1e-3f);
  for (Param& p : actor.Params()) p.grad->setConstant(1.0f);
  for (Param& p : critic.Params()) p.grad->setConstant(-1.0f);
  std::vector<float> a0, c0, a1, c1;
  actor.GetFlat(&a0);
  critic.GetFlat(&c0);
  critic_opt.Step();
  actor.GetFlat(&a1);
  critic.GetFlat(&c1);
  EXPECT_EQ(a1, a0);
  for (size_t k = 0; k < c1.size(); ++k) EXPECT_NEAR(c1[k] - c0[k], 1e-3f, 1e-6f);
  actor_opt.Step();
  actor.GetFlat(&a1);
  for (size_t k = 0; k < a1.size(); ++k) EXPECT_NEAR(a1[k] - a0[k], -1e-2f, 1e-5f);
}

TEST(PresetsTest, TheTd3NetworksHaveTheArticlesShapesAndParameterCounts) {
  std::mt19937 rng(7);
  Sequential encoder = BuildFromArchitecture(CarEncoderArchitecture(), &rng);
  EXPECT_EQ(encoder.InputSize(), 4 * 84 * 84);
  EXPECT_EQ(encoder.OutputSize(), 512);
  // conv 4->16 4x4: 16 * 64 + 16; conv 16->32 4x4: 32 * 256 + 32.
  EXPECT_EQ(encoder.NumParams(), 1040 + 8224);
  Sequential actor =
      BuildFromArchitecture(Td3CarActorArchitecture({-1.0f, 0.0f, 0.0f}, {1.0f, 1.0f, 1.0f}), &rng);
  EXPECT_EQ(actor.OutputSize(), 3);
  // + LayerNorm(512) 1024, Linear 512->128 65,664, Linear 128->3 387, LayerNorm(3) 6.
  EXPECT_EQ(actor.NumParams(), 1040 + 8224 + 1024 + 65664 + 387 + 6);
  ActionValueNet critic = BuildActionValueNet(Td3CarCriticArchitecture(), 4 * 84 * 84, 3, &rng);
  // encoder + Linear 512->128 + Linear 128->3 | Linear 3->3 | Linear 6->3 + Linear 3->1.
  int64_t n = 0;
  for (Param& p : critic.Params()) n += p.value->size();
  EXPECT_EQ(n, 1040 + 8224 + 65664 + 387 + 12 + 21 + 4);
  Sequential mlp = BuildFromArchitecture(
      Td3MlpActorArchitecture(8, {256, 256}, {-1.0f, -1.0f}, {1.0f, 1.0f}), &rng);
  EXPECT_EQ(mlp.NumParams(), 8 * 256 + 256 + 256 * 256 + 256 + 256 * 2 + 2);
  ActionValueNet q = BuildActionValueNet(Td3MlpCriticArchitecture(8, 2, {256, 256}), 8, 2, &rng);
  EXPECT_EQ(q.head().InputSize(), 10);
  EXPECT_THROW(Td3MlpActorArchitecture(8, {256}, {1.0f}, {1.0f}), std::invalid_argument);
}

}  // namespace
}  // namespace rl::nn
