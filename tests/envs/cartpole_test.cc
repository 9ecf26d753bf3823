#include "envs/cartpole.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>

#include <gtest/gtest.h>

#include "envs/registry.h"
#include "tests/envs/trajectory_hash.h"

namespace rl::envs {
namespace {

using State = std::array<double, 4>;

// The equations of motion of the classic cart-pole, restated from the paper's formulas in the most
// direct form, independently of the class under test.
State ReferenceStep(const State& s, int action, bool semi_implicit) {
  const double g = 9.8;
  const double m_cart = 1.0;
  const double m_pole = 0.1;
  const double half_length = 0.5;
  const double dt = 0.02;
  const double f = action == 1 ? 10.0 : -10.0;
  const double m = m_cart + m_pole;
  const double theta = s[2];
  const double omega = s[3];
  const double a = (f + m_pole * half_length * omega * omega * std::sin(theta)) / m;
  const double theta_acc =
      (g * std::sin(theta) - std::cos(theta) * a) /
      (half_length * (4.0 / 3.0 - m_pole * std::cos(theta) * std::cos(theta) / m));
  const double x_acc = a - m_pole * half_length * theta_acc * std::cos(theta) / m;
  if (semi_implicit) {
    const double v = s[1] + dt * x_acc;
    const double w = omega + dt * theta_acc;
    return {s[0] + dt * v, v, theta + dt * w, w};
  }
  return {s[0] + dt * s[1], s[1] + dt * x_acc, theta + dt * omega, omega + dt * theta_acc};
}

// Expects the observation to be the state cast to float32.
void ExpectObservationMatchesState(const CartPole& env) {
  ASSERT_EQ(env.observation().size(), 4u);
  for (int i = 0; i < 4; ++i) {
    EXPECT_EQ(env.observation()[i], static_cast<float>(env.state()[i])) << "component " << i;
  }
}

CartPole SemiImplicitCartPole() {
  CartPoleConfig config;
  config.integrator = CartPoleIntegrator::kSemiImplicitEuler;
  return CartPole(config);
}

TEST(CartPoleTest, ThresholdsAreTheReferencesConstants) {
  // 12 degrees, as printed by python3 -c "import math; print(repr(12*2*math.pi/360))".
  EXPECT_EQ(CartPole::kThetaThresholdRadians, 0.20943951023931953);
  EXPECT_EQ(CartPole::kXThreshold, 2.4);
}

TEST(CartPoleTest, EulerStepFromRestMatchesHandComputedFractions) {
  // From the zero state with force +10: temp = 100/11, theta_acc = -(100/11) / (0.5 * 41/33) =
  // -600/41 and x_acc = 100/11 + 0.05 * (600/41) / 1.1 = 400/41. Euler moves only the velocities.
  CartPole env;
  env.set_state({0, 0, 0, 0});
  const StepResult right = env.Step(DiscreteAction(1));
  EXPECT_DOUBLE_EQ(env.state()[0], 0.0);
  EXPECT_DOUBLE_EQ(env.state()[1], 0.02 * 400.0 / 41.0);
  EXPECT_DOUBLE_EQ(env.state()[2], 0.0);
  EXPECT_DOUBLE_EQ(env.state()[3], -0.02 * 600.0 / 41.0);
  EXPECT_NEAR(env.state()[1], 0.195121951219512, 1e-14);
  EXPECT_NEAR(env.state()[3], -0.292682926829268, 1e-14);
  EXPECT_EQ(right.reward, 1.0);
  EXPECT_FALSE(right.terminated);
  EXPECT_FALSE(right.truncated);
  ExpectObservationMatchesState(env);

  // Pushing left mirrors everything.
  env.set_state({0, 0, 0, 0});
  env.Step(DiscreteAction(0));
  EXPECT_DOUBLE_EQ(env.state()[1], -0.02 * 400.0 / 41.0);
  EXPECT_DOUBLE_EQ(env.state()[3], 0.02 * 600.0 / 41.0);
}

TEST(CartPoleTest, SemiImplicitStepFromRestMovesPositionsWithTheNewVelocities) {
  CartPole env = SemiImplicitCartPole();
  env.set_state({0, 0, 0, 0});
  env.Step(DiscreteAction(1));
  EXPECT_DOUBLE_EQ(env.state()[1], 0.02 * 400.0 / 41.0);
  EXPECT_DOUBLE_EQ(env.state()[0], 0.02 * 0.02 * 400.0 / 41.0);
  EXPECT_DOUBLE_EQ(env.state()[3], -0.02 * 600.0 / 41.0);
  EXPECT_DOUBLE_EQ(env.state()[2], -0.02 * 0.02 * 600.0 / 41.0);
}

TEST(CartPoleTest, EulerStepFromAGeneralStateMatchesTheEquationsForBothActions) {
  const State start = {0.1, -0.2, 0.05, 0.3};
  // Values printed by a separate python3 implementation of the same equations.
  const State expected_left = {0.096, -0.3957976546439626, 0.056, 0.6080233136061515};
  const State expected_right = {0.096, -0.005625065781779709, 0.056, 0.02349585151852651};
  for (int action : {0, 1}) {
    CartPole env;
    env.set_state(start);
    const StepResult r = env.Step(DiscreteAction(action));
    const State reference = ReferenceStep(start, action, /*semi_implicit=*/false);
    const State& literal = action == 0 ? expected_left : expected_right;
    for (int i = 0; i < 4; ++i) {
      EXPECT_NEAR(env.state()[i], reference[i], 1e-12) << "action " << action << " component " << i;
      EXPECT_DOUBLE_EQ(env.state()[i], literal[i]) << "action " << action << " component " << i;
    }
    EXPECT_EQ(r.reward, 1.0);
    EXPECT_FALSE(r.terminated);
    ExpectObservationMatchesState(env);
  }
}

TEST(CartPoleTest, SemiImplicitStepFromAGeneralStateMatchesTheEquationsForBothActions) {
  const State start = {0.1, -0.2, 0.05, 0.3};
  const State expected_left = {0.09208404690712076, -0.3957976546439626, 0.06216046627212303,
                               0.6080233136061515};
  const State expected_right = {0.09988749868436442, -0.005625065781779709, 0.050469917030370536,
                                0.02349585151852651};
  for (int action : {0, 1}) {
    CartPole env = SemiImplicitCartPole();
    env.set_state(start);
    env.Step(DiscreteAction(action));
    const State reference = ReferenceStep(start, action, /*semi_implicit=*/true);
    const State& literal = action == 0 ? expected_left : expected_right;
    for (int i = 0; i < 4; ++i) {
      EXPECT_NEAR(env.state()[i], reference[i], 1e-12) << "action " << action << " component " << i;
      EXPECT_DOUBLE_EQ(env.state()[i], literal[i]) << "action " << action << " component " << i;
    }
  }
}

TEST(CartPoleTest, ManyStepsFollowTheReferenceEquations) {
  // A long trajectory, away from the termination bounds' effect on anything but the flag.
  CartPole env;
  env.Reset(3);
  State reference = env.state();
  std::mt19937_64 policy(11);
  for (int t = 0; t < 200; ++t) {
    const int action = static_cast<int>(policy() >> 63);
    env.Step(DiscreteAction(action));
    reference = ReferenceStep(reference, action, /*semi_implicit=*/false);
    for (int i = 0; i < 4; ++i) ASSERT_NEAR(env.state()[i], reference[i], 1e-9) << "step " << t;
  }
}

TEST(CartPoleTest, CartExactlyAtTheBoundaryDoesNotTerminate) {
  // With zero velocities an Euler step leaves x and theta exactly where they are.
  for (double x : {2.4, -2.4}) {
    CartPole env;
    env.set_state({x, 0, 0, 0});
    const StepResult r = env.Step(DiscreteAction(1));
    EXPECT_EQ(env.state()[0], x);
    EXPECT_FALSE(r.terminated) << "x = " << x;
    EXPECT_EQ(r.reward, 1.0);
  }
}

TEST(CartPoleTest, CartPastTheBoundaryTerminates) {
  for (double x : {std::nextafter(2.4, 3.0), std::nextafter(-2.4, -3.0), 2.41, -2.5}) {
    CartPole env;
    env.set_state({x, 0, 0, 0});
    const StepResult r = env.Step(DiscreteAction(0));
    EXPECT_TRUE(r.terminated) << "x = " << x;
    EXPECT_EQ(r.reward, 1.0) << "the terminating step is still rewarded";
    EXPECT_FALSE(r.truncated);
  }
}

TEST(CartPoleTest, PoleExactlyAtTwelveDegreesDoesNotTerminate) {
  const double threshold = 0.20943951023931953;  // 12 degrees in radians.
  for (double theta : {threshold, -threshold}) {
    CartPole env;
    env.set_state({0, 0, theta, 0});
    const StepResult r = env.Step(DiscreteAction(theta > 0 ? 1 : 0));
    EXPECT_EQ(env.state()[2], theta);
    EXPECT_FALSE(r.terminated) << "theta = " << theta;
  }
}

TEST(CartPoleTest, PolePastTwelveDegreesTerminates) {
  const double threshold = 0.20943951023931953;  // 12 degrees in radians.
  for (double theta : {std::nextafter(threshold, 1.0), std::nextafter(-threshold, -1.0), 0.25}) {
    CartPole env;
    env.set_state({0, 0, theta, 0});
    const StepResult r = env.Step(DiscreteAction(1));
    EXPECT_TRUE(r.terminated) << "theta = " << theta;
    EXPECT_EQ(r.reward, 1.0);
  }
}

TEST(CartPoleTest, PoleFallsOverUnderAConstantPush) {
  // Always pushing right tips the pole left; the episode must end with |theta| > 12 degrees.
  CartPole env;
  env.Reset(5);
  int steps = 0;
  StepResult r;
  do {
    r = env.Step(DiscreteAction(1));
    ++steps;
  } while (!r.terminated && steps < 100);
  EXPECT_TRUE(r.terminated);
  EXPECT_LT(env.state()[2], -CartPole::kThetaThresholdRadians);
  EXPECT_LT(steps, 20);
}

TEST(CartPoleTest, StepsAfterTerminationGiveZeroRewardAndWarnOnce) {
  CartPole env;
  env.set_state({2.5, 0, 0, 0});
  EXPECT_EQ(env.Step(DiscreteAction(0)).reward, 1.0);

  testing::internal::CaptureStderr();
  const StepResult first_after = env.Step(DiscreteAction(0));
  const std::string first_warning = testing::internal::GetCapturedStderr();
  EXPECT_TRUE(first_after.terminated);
  EXPECT_EQ(first_after.reward, 0.0);
  EXPECT_NE(first_warning.find("terminated"), std::string::npos) << first_warning;

  testing::internal::CaptureStderr();
  const StepResult second_after = env.Step(DiscreteAction(0));
  EXPECT_EQ(testing::internal::GetCapturedStderr(), "");
  EXPECT_EQ(second_after.reward, 0.0);

  // A new episode gets a fresh terminating reward and a fresh warning.
  env.Reset(1);
  env.set_state({2.5, 0, 0, 0});
  EXPECT_EQ(env.Step(DiscreteAction(0)).reward, 1.0);
  testing::internal::CaptureStderr();
  EXPECT_EQ(env.Step(DiscreteAction(0)).reward, 0.0);
  EXPECT_NE(testing::internal::GetCapturedStderr(), "");
}

TEST(CartPoleTest, ReenteringTheBoundsAfterTerminationRewardsAgainButNotASecondFall) {
  CartPole env;
  env.set_state({2.5, 0, 0, 0});
  EXPECT_EQ(env.Step(DiscreteAction(0)).reward, 1.0);
  env.set_state({0, 0, 0, 0});
  const StepResult inside = env.Step(DiscreteAction(0));
  EXPECT_FALSE(inside.terminated);
  EXPECT_EQ(inside.reward, 1.0);
  env.set_state({2.5, 0, 0, 0});
  testing::internal::CaptureStderr();
  const StepResult fell_again = env.Step(DiscreteAction(0));
  testing::internal::GetCapturedStderr();
  EXPECT_TRUE(fell_again.terminated);
  EXPECT_EQ(fell_again.reward, 0.0);
}

TEST(CartPoleTest, SuttonBartoRewardIsZeroAliveAndMinusOneFromTermination) {
  CartPoleConfig config;
  config.sutton_barto_reward = true;
  CartPole env(config);
  env.set_state({0, 0, 0, 0});
  EXPECT_EQ(env.Step(DiscreteAction(0)).reward, 0.0);
  env.set_state({2.5, 0, 0, 0});
  EXPECT_EQ(env.Step(DiscreteAction(0)).reward, -1.0);
  testing::internal::CaptureStderr();
  EXPECT_EQ(env.Step(DiscreteAction(0)).reward, -1.0);
  testing::internal::GetCapturedStderr();
}

TEST(CartPoleTest, ResetDrawsEachComponentUniformlyWithinFiveHundredths) {
  CartPole env;
  env.Reset(2024);
  constexpr int kResets = 20000;
  std::array<double, 4> sum{}, sum_sq{}, lo{}, hi{};
  lo.fill(1);
  hi.fill(-1);
  for (int n = 0; n < kResets; ++n) {
    env.Reset();
    for (int i = 0; i < 4; ++i) {
      const double v = env.state()[i];
      ASSERT_GE(v, -0.05);
      ASSERT_LE(v, 0.05);
      ASSERT_GE(env.observation()[i], -0.05f);
      ASSERT_LE(env.observation()[i], 0.05f);
      sum[i] += v;
      sum_sq[i] += v * v;
      lo[i] = std::min(lo[i], v);
      hi[i] = std::max(hi[i], v);
    }
    ExpectObservationMatchesState(env);
  }
  // U(-0.05, 0.05) has mean 0 and variance 0.1^2 / 12; the mean's standard error is ~2e-4.
  for (int i = 0; i < 4; ++i) {
    const double mean = sum[i] / kResets;
    EXPECT_NEAR(mean, 0.0, 1.5e-3) << "component " << i;
    EXPECT_NEAR(sum_sq[i] / kResets - mean * mean, 0.01 / 12, 0.01 / 12 * 0.05) << i;
    EXPECT_LT(lo[i], -0.0495) << i;
    EXPECT_GT(hi[i], 0.0495) << i;
  }
}

TEST(CartPoleTest, ResetBoundsCanBeConfigured) {
  CartPoleConfig config;
  config.reset_low = 0.2;
  config.reset_high = 0.3;
  CartPole env(config);
  env.Reset(9);
  for (int n = 0; n < 100; ++n) {
    env.Reset();
    for (double v : env.state()) {
      EXPECT_GE(v, 0.2);
      EXPECT_LE(v, 0.3);
    }
  }
  config.reset_low = 0.4;
  EXPECT_THROW(CartPole{config}, std::invalid_argument);
  config.reset_low = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(CartPole{config}, std::invalid_argument);
}

// Hashes the observations, rewards and flags of `episodes` random-policy episodes of a
// MakeEnv("CartPole-v1") env seeded once with `seed`.
uint64_t RandomTrajectoryHash(uint64_t seed, int episodes) {
  auto env = MakeEnv("CartPole-v1");
  std::mt19937_64 policy(77);
  TrajectoryHash hash;
  env->Reset(seed);
  for (int e = 0; e < episodes; ++e) {
    if (e > 0) env->Reset();
    for (float v : env->observation()) hash.Add(v);
    StepResult r;
    do {
      r = env->Step(DiscreteAction(static_cast<int>(policy() >> 63)));
      for (float v : env->observation()) hash.Add(v);
      hash.Add(r.reward);
      hash.Add(r.terminated);
      hash.Add(r.truncated);
    } while (!r.terminated && !r.truncated);
  }
  return hash.value();
}

TEST(CartPoleTest, SameSeedGivesIdenticalObservationsAndTrajectories) {
  CartPole a;
  CartPole b;
  a.Reset(42);
  b.Reset(42);
  EXPECT_EQ(a.state(), b.state());
  for (int t = 0; t < 50; ++t) {
    a.Step(DiscreteAction(t % 3 == 0 ? 1 : 0));
    b.Step(DiscreteAction(t % 3 == 0 ? 1 : 0));
    ASSERT_EQ(a.state(), b.state()) << "step " << t;
  }
  EXPECT_EQ(RandomTrajectoryHash(42, 20), RandomTrajectoryHash(42, 20));
}

TEST(CartPoleTest, DifferentSeedsGiveDifferentStates) {
  CartPole a;
  CartPole b;
  CartPole c;
  a.Reset(1);
  b.Reset(2);
  c.Reset(1 + (uint64_t{1} << 32));  // Differs from seed 1 only in the high 32 bits.
  EXPECT_NE(a.state(), b.state());
  EXPECT_NE(a.state(), c.state());
  EXPECT_NE(RandomTrajectoryHash(1, 20), RandomTrajectoryHash(2, 20));
}

TEST(CartPoleTest, ResetWithoutSeedContinuesTheSeededStream) {
  CartPole a;
  a.Reset(7);
  const State first = a.state();
  a.Reset();
  const State second = a.state();
  EXPECT_NE(first, second);

  // Stepping does not consume randomness, so the stream continues identically.
  CartPole b;
  b.Reset(7);
  EXPECT_EQ(b.state(), first);
  for (int t = 0; t < 10; ++t) b.Step(DiscreteAction(t % 2));
  b.Reset();
  EXPECT_EQ(b.state(), second);

  // Reseeding restarts the stream.
  a.Reset(7);
  EXPECT_EQ(a.state(), first);
}

TEST(CartPoleTest, UnseededResetStillDrawsAValidState) {
  CartPole env;
  env.Reset();
  for (double v : env.state()) {
    EXPECT_GE(v, -0.05);
    EXPECT_LE(v, 0.05);
  }
  EXPECT_NO_THROW(env.Step(DiscreteAction(0)));
}

TEST(CartPoleTest, RandomPolicyLastsAboutTwentyTwoStepsPerEpisode) {
  auto env = MakeEnv("CartPole-v1");
  std::mt19937_64 policy(12345);
  env->Reset(2025);
  constexpr int kEpisodes = 5000;
  int64_t total_steps = 0;
  double total_reward = 0;
  for (int e = 0; e < kEpisodes; ++e) {
    if (e > 0) env->Reset();
    StepResult r;
    do {
      r = env->Step(DiscreteAction(static_cast<int>(policy() >> 63)));
      ++total_steps;
      total_reward += r.reward;
    } while (!r.terminated && !r.truncated);
  }
  const double mean_length = static_cast<double>(total_steps) / kEpisodes;
  EXPECT_GE(mean_length, 18.0);
  EXPECT_LE(mean_length, 27.0);
  // Every step of an episode, including the last, is rewarded 1.
  EXPECT_EQ(total_reward, static_cast<double>(total_steps));
}

TEST(CartPoleTest, InvalidActionThrowsAndLeavesTheStateUnchanged) {
  CartPole env;
  env.Reset(0);
  const State before = env.state();
  EXPECT_THROW(env.Step(DiscreteAction(2)), std::invalid_argument);
  EXPECT_THROW(env.Step(DiscreteAction(-1)), std::invalid_argument);
  EXPECT_EQ(env.state(), before);
  try {
    env.Step(DiscreteAction(5));
    FAIL() << "expected std::invalid_argument";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find('5'), std::string::npos) << e.what();
  }
}

TEST(CartPoleTest, StepBeforeResetThrows) {
  CartPole env;
  EXPECT_THROW(env.Step(DiscreteAction(0)), std::logic_error);
}

}  // namespace
}  // namespace rl::envs
