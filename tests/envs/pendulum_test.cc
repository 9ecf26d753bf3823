#include "envs/pendulum.h"

#include <cmath>
#include <numbers>
#include <stdexcept>
#include <vector>

#include <gtest/gtest.h>

#include "envs/registry.h"

namespace rl::envs {
namespace {

constexpr double kPi = std::numbers::pi;

StepResult Torque(Pendulum* env, float u) {
  const float a[] = {u};
  return env->StepContinuous(a);
}

// One step by hand from (th, thdot) with torque u: cost from the old state, then the semi-implicit
// update with g = 10, m = l = 1, dt = 0.05.
TEST(PendulumTest, StepsFollowTheEquationsComputedByHand) {
  Pendulum env;
  env.SetState(0.5, -1.0);
  const StepResult r = Torque(&env, 1.5f);
  const double cost = 0.5 * 0.5 + 0.1 * 1.0 + 0.001 * 1.5 * 1.5;
  EXPECT_DOUBLE_EQ(r.reward, -cost);
  const double thdot = -1.0 + (3 * 10.0 / 2 * std::sin(0.5) + 3.0 * 1.5) * 0.05;
  EXPECT_DOUBLE_EQ(env.theta_dot(), thdot);
  EXPECT_DOUBLE_EQ(env.theta(), 0.5 + thdot * 0.05);
  EXPECT_FALSE(r.terminated);
  EXPECT_FALSE(r.truncated);
  const auto obs = env.observation();
  ASSERT_EQ(obs.size(), 3U);
  EXPECT_EQ(obs[0], static_cast<float>(std::cos(env.theta())));
  EXPECT_EQ(obs[1], static_cast<float>(std::sin(env.theta())));
  EXPECT_EQ(obs[2], static_cast<float>(thdot));
}

TEST(PendulumTest, ClipsTheTorqueAndTheSpeed) {
  Pendulum a, b;
  a.SetState(1.0, 0.0);
  b.SetState(1.0, 0.0);
  const StepResult ra = Torque(&a, 7.0f);
  const StepResult rb = Torque(&b, 2.0f);
  EXPECT_EQ(ra.reward, rb.reward);  // the cost uses the clipped torque
  EXPECT_EQ(a.theta(), b.theta());
  a.SetState(kPi / 2, 7.9);  // gravity and torque push the speed past 8
  Torque(&a, 2.0f);
  EXPECT_EQ(a.theta_dot(), 8.0);
  a.SetState(-kPi / 2, -7.9);
  Torque(&a, -2.0f);
  EXPECT_EQ(a.theta_dot(), -8.0);
}

TEST(PendulumTest, NormalisesAnglesWithPythonsModulo) {
  EXPECT_DOUBLE_EQ(Pendulum::AngleNormalize(0.0), 0.0);
  EXPECT_NEAR(Pendulum::AngleNormalize(2 * kPi + 0.25), 0.25, 1e-12);
  EXPECT_NEAR(Pendulum::AngleNormalize(-2 * kPi - 0.25), -0.25, 1e-12);
  EXPECT_NEAR(Pendulum::AngleNormalize(-0.25), -0.25, 1e-12);
  // pi maps to -pi: ((pi + pi) mod 2 pi) - pi.
  EXPECT_NEAR(Pendulum::AngleNormalize(kPi), -kPi, 1e-12);
  EXPECT_NEAR(Pendulum::AngleNormalize(3 * kPi), -kPi, 1e-12);
  // The cost of hanging straight down at rest with no torque is pi^2, the worst angle cost.
  Pendulum env;
  env.SetState(kPi, 0.0);
  EXPECT_NEAR(Torque(&env, 0.0f).reward, -kPi * kPi, 1e-12);
}

TEST(PendulumTest, ResetsUniformlyInItsBoundsAndIsDeterministicForASeed) {
  Pendulum env;
  double min_th = 10, max_th = -10, min_v = 10, max_v = -10;
  for (uint64_t seed = 0; seed < 2000; ++seed) {
    env.Reset(seed);
    min_th = std::min(min_th, env.theta());
    max_th = std::max(max_th, env.theta());
    min_v = std::min(min_v, env.theta_dot());
    max_v = std::max(max_v, env.theta_dot());
  }
  EXPECT_GE(min_th, -kPi);
  EXPECT_LT(min_th, -kPi + 0.05);
  EXPECT_LE(max_th, kPi);
  EXPECT_GT(max_th, kPi - 0.05);
  EXPECT_GE(min_v, -1.0);
  EXPECT_LT(min_v, -0.95);
  EXPECT_LE(max_v, 1.0);
  EXPECT_GT(max_v, 0.95);
  Pendulum a, b;
  a.Reset(7);
  b.Reset(7);
  for (int t = 0; t < 50; ++t) {
    Torque(&a, 0.3f);
    Torque(&b, 0.3f);
  }
  EXPECT_EQ(a.theta(), b.theta());
}

TEST(PendulumTest, RefusesDiscreteStepsAndBadActions) {
  Pendulum env;
  EXPECT_THROW(Torque(&env, 1.0f), std::logic_error);  // before Reset
  env.Reset(1);
  EXPECT_THROW(env.Step(0), std::logic_error);
  const float two[] = {0.0f, 1.0f};
  EXPECT_THROW(env.StepContinuous(two), std::invalid_argument);
  EXPECT_THROW(Torque(&env, std::nanf("")), std::invalid_argument);
}

TEST(PendulumTest, TheRegistryCutsEpisodesAt200Steps) {
  auto env = MakeEnv("Pendulum-v1");
  env->Reset(3);
  const float zero[] = {0.0f};
  double total = 0;
  int steps = 0;
  for (;;) {
    const StepResult r = env->Act(zero);
    total += r.reward;
    ++steps;
    EXPECT_GE(r.reward, -16.2736044);
    EXPECT_LE(r.reward, 0.0);
    if (r.terminated || r.truncated) {
      EXPECT_FALSE(r.terminated);
      break;
    }
  }
  EXPECT_EQ(steps, 200);
  EXPECT_LT(total, 0.0);
}

// The rod's colour at a point of the 500 x 500 image.
bool IsRod(const std::vector<uint8_t>& rgb, int x, int y) {
  const size_t at = (static_cast<size_t>(y) * 500 + static_cast<size_t>(x)) * 3;
  return rgb[at] == 204 && rgb[at + 1] == 77 && rgb[at + 2] == 77;
}

TEST(PendulumTest, RendersTheRodAtItsAngleAndTheAxleInBlack) {
  Pendulum env;
  std::vector<uint8_t> rgb;
  int w = 0, h = 0;
  env.SetState(0.0, 0.0);  // upright: the rod goes up from the centre
  env.Render(&rgb, &w, &h);
  ASSERT_EQ(w, 500);
  ASSERT_EQ(h, 500);
  // One world unit is 500 / 4.4 = 113.6 pixels: half the rod is 57 pixels above the centre.
  EXPECT_TRUE(IsRod(rgb, 250, 250 - 57));
  EXPECT_FALSE(IsRod(rgb, 250, 250 + 57));
  EXPECT_FALSE(IsRod(rgb, 250 - 57, 250));
  const size_t centre = (250 * 500 + 250) * 3;
  EXPECT_EQ(rgb[centre], 0);  // the axle
  EXPECT_EQ(rgb[centre + 1], 0);
  EXPECT_EQ(rgb[0], 255);      // white background
  env.SetState(kPi / 2, 0.0);  // a quarter turn counter-clockwise: the rod points left
  env.Render(&rgb, &w, &h);
  EXPECT_TRUE(IsRod(rgb, 250 - 57, 250));
  EXPECT_FALSE(IsRod(rgb, 250, 250 - 57));
  std::vector<uint8_t> small;
  env.RenderSized(64, 48, &small);
  EXPECT_EQ(small.size(), 64U * 48U * 3U);
}

}  // namespace
}  // namespace rl::envs
