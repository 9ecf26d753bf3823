#include "envs/pendulum.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>
#include <random>
#include <span>
#include <stdexcept>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "envs/registry.h"
#include "envs/rng.h"

namespace rl::envs {
namespace {

constexpr double kPi = std::numbers::pi;
// The lowest reward: hanging down (angle cost pi^2) at full speed with full torque.
constexpr double kWorstReward = -(kPi * kPi + 0.1 * (8.0 * 8.0) + 0.001 * (2.0 * 2.0));

StepResult Torque(Pendulum& env, float u) {
  const float action[] = {u};
  return env.Step(action);
}

// The reference's step written out: cost of the old state, then semi-implicit Euler with
// g = 10, m = l = 1, dt = 0.05. Returns {reward, new theta, new theta_dot}.
struct Expected {
  double reward;
  double theta;
  double theta_dot;
};
Expected ByHand(double th, double thdot, double u) {
  const double normalized = std::fmod(th + kPi, 2 * kPi) - kPi;  // th in [-pi, pi) here.
  const double cost = normalized * normalized + 0.1 * (thdot * thdot) + 0.001 * (u * u);
  double new_thdot = thdot + (3 * 10.0 / 2 * std::sin(th) + 3.0 * u) * 0.05;
  new_thdot = std::clamp(new_thdot, -8.0, 8.0);
  return {-cost, th + new_thdot * 0.05, new_thdot};
}

TEST(PendulumTest, StepsFollowTheEquationsComputedByHand) {
  Pendulum env;
  env.SetState(0.5, -1.0);
  // Values printed by Python for the reference's formulas from (0.5, -1.0) with u = 1.5.
  const StepResult first = Torque(env, 1.5f);
  EXPECT_DOUBLE_EQ(first.reward, -0.35224999999999995);  // -(0.25 + 0.1 + 0.00225)
  EXPECT_DOUBLE_EQ(env.theta_dot(), -0.41543084604684777);
  EXPECT_DOUBLE_EQ(env.theta(), 0.4792284576976576);
  EXPECT_FALSE(first.terminated);
  EXPECT_FALSE(first.truncated);
  // The same by the formulas: the angle moves with the new velocity (semi-implicit), and the
  // reward is the cost of the state before the step.
  const Expected e1 = ByHand(0.5, -1.0, 1.5);
  EXPECT_DOUBLE_EQ(first.reward, e1.reward);
  EXPECT_DOUBLE_EQ(env.theta_dot(), e1.theta_dot);
  EXPECT_DOUBLE_EQ(env.theta(), e1.theta);
  EXPECT_NE(env.theta(), 0.5 + -1.0 * 0.05);  // Not explicit Euler.

  // A second step with a negative torque continues from the new state.
  const StepResult second = Torque(env, -0.75f);
  const Expected e2 = ByHand(e1.theta, e1.theta_dot, -0.75);
  EXPECT_DOUBLE_EQ(second.reward, e2.reward);
  EXPECT_DOUBLE_EQ(second.reward, -0.2474806934519955);
  EXPECT_DOUBLE_EQ(env.theta_dot(), -0.1821098330010099);
  EXPECT_DOUBLE_EQ(env.theta(), 0.4701229660476071);
  ASSERT_TRUE(env.last_u().has_value());
  EXPECT_EQ(*env.last_u(), -0.75);
}

TEST(PendulumTest, GravityComesFromTheConfig) {
  Pendulum moon(PendulumConfig{.g = 1.62});
  moon.SetState(1.0, 0.0);
  Torque(moon, 0.0f);
  EXPECT_DOUBLE_EQ(moon.theta_dot(), 3 * 1.62 / 2 * std::sin(1.0) * 0.05);
  EXPECT_THROW(Pendulum(PendulumConfig{.g = std::nan("")}), std::invalid_argument);
  EXPECT_THROW(Pendulum(PendulumConfig{.x_init = -1.0}), std::invalid_argument);
  EXPECT_THROW(Pendulum(PendulumConfig{.y_init = std::numeric_limits<double>::infinity()}),
               std::invalid_argument);
}

TEST(PendulumTest, ClipsTheTorqueToPlusMinusTwo) {
  const float inf = std::numeric_limits<float>::infinity();
  for (const auto& [given, clipped] : std::vector<std::pair<float, float>>{
           {7.0f, 2.0f}, {2.5f, 2.0f}, {inf, 2.0f}, {-3.0f, -2.0f}, {-inf, -2.0f}}) {
    SCOPED_TRACE(given);
    Pendulum a;
    Pendulum b;
    a.SetState(1.0, 0.5);
    b.SetState(1.0, 0.5);
    const StepResult ra = Torque(a, given);
    const StepResult rb = Torque(b, clipped);
    EXPECT_EQ(ra.reward, rb.reward);          // The cost uses the clipped torque ...
    EXPECT_EQ(a.theta_dot(), b.theta_dot());  // ... and so do the dynamics.
    EXPECT_EQ(a.theta(), b.theta());
    ASSERT_TRUE(a.last_u().has_value());
    EXPECT_EQ(*a.last_u(), clipped);
    EXPECT_DOUBLE_EQ(ra.reward, ByHand(1.0, 0.5, clipped).reward);
  }
  // Inside the bounds the torque is used as given.
  Pendulum env;
  env.SetState(1.0, 0.5);
  Torque(env, 1.25f);
  ASSERT_TRUE(env.last_u().has_value());
  EXPECT_EQ(*env.last_u(), 1.25);
  EXPECT_DOUBLE_EQ(env.theta_dot(), ByHand(1.0, 0.5, 1.25).theta_dot);
}

TEST(PendulumTest, ClipsTheSpeedAtEight) {
  Pendulum env;
  // Gravity and torque push the speed to 7.9 + (15 + 6) * 0.05 = 8.95, clipped to 8; the angle
  // moves with the clipped speed.
  env.SetState(kPi / 2, 7.9);
  Torque(env, 2.0f);
  EXPECT_EQ(env.theta_dot(), 8.0);
  EXPECT_DOUBLE_EQ(env.theta(), kPi / 2 + 8.0 * 0.05);
  EXPECT_EQ(env.observation()[2], 8.0f);
  env.SetState(-kPi / 2, -7.9);
  Torque(env, -2.0f);
  EXPECT_EQ(env.theta_dot(), -8.0);
  EXPECT_DOUBLE_EQ(env.theta(), -kPi / 2 - 8.0 * 0.05);
  // Just below the limit nothing is clipped.
  env.SetState(0.0, 7.0);
  Torque(env, 1.0f);
  EXPECT_DOUBLE_EQ(env.theta_dot(), 7.15);
}

TEST(PendulumTest, NormalisesAnglesWithPythonsModulo) {
  // Python's ((x + pi) % (2 pi)) - pi, printed for each input.
  EXPECT_EQ(Pendulum::AngleNormalize(0.0), 0.0);
  EXPECT_EQ(Pendulum::AngleNormalize(-0.25), -0.25);
  EXPECT_DOUBLE_EQ(Pendulum::AngleNormalize(-2 * kPi - 0.25), -0.25);
  EXPECT_DOUBLE_EQ(Pendulum::AngleNormalize(7.0), 0.7168146928204138);
  EXPECT_DOUBLE_EQ(Pendulum::AngleNormalize(-7.0), -0.7168146928204138);
  EXPECT_DOUBLE_EQ(Pendulum::AngleNormalize(100.0), -0.5309649148733762);
  // Exactly pi and -pi (and odd multiples) map to -pi: the interval is [-pi, pi).
  EXPECT_EQ(Pendulum::AngleNormalize(kPi), -kPi);
  EXPECT_EQ(Pendulum::AngleNormalize(-kPi), -kPi);
  EXPECT_EQ(Pendulum::AngleNormalize(3 * kPi), -kPi);
  EXPECT_EQ(Pendulum::AngleNormalize(-3 * kPi), -kPi);
  // Around the wrap: one ulp above pi wraps to -pi, one ulp below -pi to +pi (the remainder of a
  // tiny negative number rounds up to 2 pi in Python too), one ulp inside -pi stays.
  EXPECT_EQ(Pendulum::AngleNormalize(std::nextafter(kPi, 4.0)), -kPi);
  EXPECT_EQ(Pendulum::AngleNormalize(std::nextafter(kPi, 0.0)), -kPi);
  EXPECT_EQ(Pendulum::AngleNormalize(std::nextafter(-kPi, -4.0)), kPi);
  EXPECT_EQ(Pendulum::AngleNormalize(std::nextafter(-kPi, 0.0)), -3.1415926535897927);
  EXPECT_EQ(Pendulum::AngleNormalize(kPi - 1e-12), 3.141592653588793);

  // The cost wraps the angle: a full turn more or less costs the same.
  Pendulum a;
  Pendulum b;
  a.SetState(0.3, 0.0);
  b.SetState(0.3 - 4 * kPi, 0.0);
  EXPECT_NEAR(Torque(a, 0.0f).reward, Torque(b, 0.0f).reward, 1e-12);
  EXPECT_NEAR(a.theta() - b.theta(), 4 * kPi, 1e-12);  // The state itself is not wrapped.
}

TEST(PendulumTest, RewardsLieBetweenTheWorstCaseAndZero) {
  EXPECT_NEAR(kWorstReward, -16.2736044, 1e-7);
  Pendulum env;
  // Upright at rest without torque: no cost at all.
  env.SetState(0.0, 0.0);
  EXPECT_EQ(Torque(env, 0.0f).reward, 0.0);
  // Hanging down at full speed with full torque: the worst reward.
  env.SetState(kPi, 8.0);
  EXPECT_DOUBLE_EQ(Torque(env, 2.0f).reward, kWorstReward);
  env.SetState(-kPi, -8.0);
  EXPECT_DOUBLE_EQ(Torque(env, -5.0f).reward, kWorstReward);
  // Random states and torques, well beyond the bounds.
  std::mt19937_64 rng(12345);
  env.Reset(3);
  double lowest = 0;
  for (int t = 0; t < 20000; ++t) {
    if (t % 100 == 0) {
      env.SetState(UniformDouble(rng, -20.0, 20.0), UniformDouble(rng, -8.0, 8.0));
    }
    const double reward = Torque(env, static_cast<float>(UniformDouble(rng, -4.0, 4.0))).reward;
    ASSERT_GE(reward, kWorstReward);
    ASSERT_LE(reward, 0.0);
    lowest = std::min(lowest, reward);
  }
  EXPECT_LT(lowest, -10.0);  // The sweep reaches far into the range.
}

TEST(PendulumTest, ObservationIsCosSinAndSpeedAsFloat) {
  Pendulum env;
  env.SetState(2.0, -3.5);
  std::span<const float> obs = env.observation();
  ASSERT_EQ(obs.size(), 3U);
  EXPECT_EQ(obs[0], static_cast<float>(std::cos(2.0)));
  EXPECT_EQ(obs[1], static_cast<float>(std::sin(2.0)));
  EXPECT_EQ(obs[2], -3.5f);
  // After a step it follows the new state; theta is not wrapped, cos and sin need no wrapping.
  env.SetState(10.0, 1.0);
  Torque(env, 0.5f);
  obs = env.observation();
  EXPECT_EQ(obs[0], static_cast<float>(std::cos(env.theta())));
  EXPECT_EQ(obs[1], static_cast<float>(std::sin(env.theta())));
  EXPECT_EQ(obs[2], static_cast<float>(env.theta_dot()));
  // After a Reset too.
  env.Reset(11);
  obs = env.observation();
  EXPECT_EQ(obs[0], static_cast<float>(std::cos(env.theta())));
  EXPECT_EQ(obs[1], static_cast<float>(std::sin(env.theta())));
  EXPECT_EQ(obs[2], static_cast<float>(env.theta_dot()));
  EXPECT_FLOAT_EQ(obs[0] * obs[0] + obs[1] * obs[1], 1.0f);
}

TEST(PendulumTest, ResetDrawsThetaThenSpeedUniformlyWithinTheBounds) {
  // The draws themselves: theta first, then theta_dot, from the seeded stream.
  std::mt19937_64 rng;
  SeedRng(42, rng);
  const double theta = UniformDouble(rng, -kPi, kPi);
  const double theta_dot = UniformDouble(rng, -1.0, 1.0);
  Pendulum env;
  env.Reset(42);
  EXPECT_EQ(env.theta(), theta);
  EXPECT_EQ(env.theta_dot(), theta_dot);
  EXPECT_FALSE(env.last_u().has_value());

  // Over many seeds the draws fill [-pi, pi] x [-1, 1] and stay inside.
  double min_th = 10;
  double max_th = -10;
  double min_v = 10;
  double max_v = -10;
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

  // The reset options x_init and y_init narrow both ranges symmetrically.
  Pendulum narrow(PendulumConfig{.x_init = 0.5, .y_init = 0.1});
  for (uint64_t seed = 0; seed < 500; ++seed) {
    narrow.Reset(seed);
    ASSERT_LE(std::abs(narrow.theta()), 0.5);
    ASSERT_LE(std::abs(narrow.theta_dot()), 0.1);
  }
  // A Reset forgets the last torque.
  Torque(narrow, 1.0f);
  ASSERT_TRUE(narrow.last_u().has_value());
  narrow.Reset();
  EXPECT_FALSE(narrow.last_u().has_value());
}

TEST(PendulumTest, SameSeedGivesTheSameTrajectory) {
  // Two envs from the same seed, through several episodes (unseeded Resets continue the stream).
  Pendulum a;
  Pendulum b;
  Pendulum c;
  a.Reset(7);
  b.Reset(7);
  c.Reset(8);
  EXPECT_NE(a.theta(), c.theta());
  std::mt19937_64 torques(99);
  for (int episode = 0; episode < 3; ++episode) {
    if (episode > 0) {
      a.Reset();
      b.Reset();
    }
    for (int t = 0; t < 200; ++t) {
      const auto u = static_cast<float>(UniformDouble(torques, -2.0, 2.0));
      const StepResult ra = Torque(a, u);
      const StepResult rb = Torque(b, u);
      ASSERT_EQ(ra.reward, rb.reward);
      ASSERT_EQ(a.theta(), b.theta());
      ASSERT_EQ(a.theta_dot(), b.theta_dot());
    }
  }
  // A second episode starts elsewhere than the first.
  Pendulum d;
  d.Reset(7);
  const double first = d.theta();
  d.Reset();
  EXPECT_NE(d.theta(), first);
}

TEST(PendulumTest, NeverTerminatesOrTruncatesByItself) {
  Pendulum env;
  env.Reset(5);
  for (int t = 0; t < 1000; ++t) {
    const StepResult r = Torque(env, t % 2 == 0 ? 2.0f : -2.0f);
    ASSERT_FALSE(r.terminated);
    ASSERT_FALSE(r.truncated);
  }
}

TEST(PendulumTest, RefusesActionsOfTheWrongWidthAndNaN) {
  Pendulum env;
  env.SetState(0.25, 0.5);
  const float two[] = {0.0f, 1.0f};
  EXPECT_THROW(env.Step(two), std::invalid_argument);
  EXPECT_THROW(env.Step(std::span<const float>()), std::invalid_argument);
  EXPECT_THROW(Torque(env, std::nanf("")), std::invalid_argument);
  // The state is unchanged and the env still works.
  EXPECT_EQ(env.theta(), 0.25);
  EXPECT_EQ(env.theta_dot(), 0.5);
  EXPECT_FALSE(env.last_u().has_value());
  EXPECT_NO_THROW(Torque(env, 0.0f));
}

TEST(PendulumTest, RefusesStepsBeforeReset) {
  Pendulum env;
  try {
    Torque(env, 1.0f);
    FAIL() << "expected std::logic_error";
  } catch (const std::logic_error& e) {
    EXPECT_STREQ(e.what(), "Pendulum-v1: call Reset() before Step()");
  }
  env.Reset(1);
  EXPECT_NO_THROW(Torque(env, 1.0f));
}

TEST(PendulumTest, TheRegistryCutsEpisodesAt200Steps) {
  auto env = MakeEnv("Pendulum-v1");
  env->Reset(3);
  const float zero[] = {0.0f};
  int steps = 0;
  for (;;) {
    const StepResult r = env->Step(zero);
    ++steps;
    ASSERT_GE(r.reward, kWorstReward);
    ASSERT_LE(r.reward, 0.0);
    ASSERT_FALSE(r.terminated);
    if (r.truncated) break;
    ASSERT_LT(steps, 200);
  }
  EXPECT_EQ(steps, 200);
}

}  // namespace
}  // namespace rl::envs
