#include "envs/box2d/lunar_lander.h"

#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <memory>
#include <numbers>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "envs/registry.h"
#include "envs/time_limit.h"
#include "tests/envs/trajectory_hash.h"

namespace rl::envs {
namespace {

using State = std::array<double, 8>;

LunarLander ContinuousLander() { return LunarLander(LunarLanderConfig{.continuous = true}); }

// The shaping potential written out from the documented formula, independently of the class.
double ReferenceShaping(const State& s) {
  return -100 * std::hypot(s[0], s[1]) - 100 * std::hypot(s[2], s[3]) - 100 * std::fabs(s[4]) +
         10 * s[6] + 10 * s[7];
}

// The height of the pad (terrain points 4 to 6 all lie on it).
double PadHeight(const LunarLander& env) { return env.terrain_y()[5]; }

// Lets the legs settle against their joint limits (the first step of an episode snaps them into
// place and leaves them swinging), then puts the lander above the pad centre, upright and at rest,
// with the legs about 1 cm above the pad (at rest on it, the origin is about 0.64 m above).
void PlaceAbovePad(LunarLander& env) {
  for (int t = 0; t < 30; ++t) env.Step(DiscreteAction(0));
  env.SetLanderKinematics(LanderKinematics{.x = 10.0, .y = PadHeight(env) + 0.65});
}

// Plays one random-policy episode of MakeEnv("LunarLander-v3") from `seed` and returns the
// observations of every step, flattened.
std::vector<float> RandomEpisode(uint64_t seed, uint64_t policy_seed) {
  auto env = MakeEnv("LunarLander-v3");
  std::mt19937_64 policy(policy_seed);
  env->Reset(seed);
  std::vector<float> trace(env->observation().begin(), env->observation().end());
  StepResult r;
  do {
    r = env->Step(DiscreteAction(static_cast<int>(policy() >> 62)));
    trace.insert(trace.end(), env->observation().begin(), env->observation().end());
    trace.push_back(static_cast<float>(r.reward));
  } while (!r.terminated && !r.truncated);
  return trace;
}

TEST(LunarLanderTest, ConfigRejectsGravityOutsideTheOpenIntervalAndNonFinitePowers) {
  for (double g : {0.0, -12.0, 1.0, -20.0, std::numeric_limits<double>::quiet_NaN()}) {
    EXPECT_THROW(LunarLander(LunarLanderConfig{.gravity = g}), std::invalid_argument) << g;
  }
  EXPECT_NO_THROW(LunarLander(LunarLanderConfig{.gravity = -11.99}));
  EXPECT_NO_THROW(LunarLander(LunarLanderConfig{.gravity = -0.5}));
  EXPECT_THROW(
      LunarLander(LunarLanderConfig{.wind_power = std::numeric_limits<double>::infinity()}),
      std::invalid_argument);
  EXPECT_THROW(
      LunarLander(LunarLanderConfig{.turbulence_power = std::numeric_limits<double>::quiet_NaN()}),
      std::invalid_argument);
}

TEST(LunarLanderTest, PowersOutsideTheRecommendedRangesAreAcceptedWithAWarning) {
  testing::internal::CaptureStderr();
  LunarLander quiet(
      LunarLanderConfig{.enable_wind = true, .wind_power = 20, .turbulence_power = 2});
  EXPECT_EQ(testing::internal::GetCapturedStderr(), "");
  testing::internal::CaptureStderr();
  LunarLander windy(LunarLanderConfig{.enable_wind = true, .wind_power = 25});
  const std::string wind_warning = testing::internal::GetCapturedStderr();
  EXPECT_NE(wind_warning.find("wind_power"), std::string::npos) << wind_warning;
  testing::internal::CaptureStderr();
  LunarLander turbulent(LunarLanderConfig{.turbulence_power = -1});
  const std::string torque_warning = testing::internal::GetCapturedStderr();
  EXPECT_NE(torque_warning.find("turbulence_power"), std::string::npos) << torque_warning;
}

TEST(LunarLanderTest, NormalisedStateOfAKnownStateMatchesHandComputedValues) {
  // x = 12 m is 2 m right of centre (W/2 = 10); y = 5 m is 1.0667 m above helipad_y + 0.6 m,
  // over H/2 = 6.667 m; velocities scale by 10/50 and 6.667/50; omega by 20/50.
  const State s = LunarLander::NormalisedState(
      LanderKinematics{.x = 12, .y = 5, .vx = 1, .vy = -2, .angle = 0.3, .angular_velocity = 0.5},
      true, false);
  EXPECT_DOUBLE_EQ(s[0], 0.2);
  EXPECT_DOUBLE_EQ(s[1], 0.16);
  EXPECT_DOUBLE_EQ(s[2], 0.2);
  EXPECT_DOUBLE_EQ(s[3], -0.26666666666666666);
  EXPECT_DOUBLE_EQ(s[4], 0.3);
  EXPECT_DOUBLE_EQ(s[5], 0.2);
  EXPECT_EQ(s[6], 1.0);
  EXPECT_EQ(s[7], 0.0);
  // The pad centre at the resting height of the legs is the origin of the first two components.
  const State origin = LunarLander::NormalisedState(
      LanderKinematics{.x = 10, .y = LunarLander::kH / 4 + 0.6}, false, true);
  EXPECT_NEAR(origin[0], 0.0, 1e-15);
  EXPECT_NEAR(origin[1], 0.0, 1e-15);
  EXPECT_EQ(origin[7], 1.0);
}

TEST(LunarLanderTest, ObservationIsTheNormalisedStateOfTheBodyInFloat32) {
  LunarLander env;
  env.Reset(3);
  env.SetLanderKinematics(
      LanderKinematics{.x = 12, .y = 5, .vx = 1, .vy = -2, .angle = 0.3, .angular_velocity = 0.5});
  const LanderKinematics k = env.lander_kinematics();
  EXPECT_EQ(k.x, 12.0);
  EXPECT_EQ(k.vy, -2.0);
  EXPECT_EQ(k.angle, static_cast<double>(0.3f));  // Box2D stores float.
  ASSERT_EQ(env.observation().size(), 8u);
  const std::array<float, 8> expected = {0.2f, 0.16f, 0.2f, -0.26666667f, 0.3f, 0.2f, 0.0f, 0.0f};
  for (int i = 0; i < 8; ++i) {
    EXPECT_FLOAT_EQ(env.observation()[i], expected[i]) << "component " << i;
    EXPECT_EQ(env.observation()[i], static_cast<float>(env.state()[i])) << "component " << i;
  }
}

TEST(LunarLanderTest, ShapingOfHandComputedStates) {
  // Distance 0.5 from the pad, speed 1, tilt 0.25 rad: -50 - 100 - 25.
  EXPECT_DOUBLE_EQ(LunarLander::Shaping({0.3, 0.4, 0.6, -0.8, -0.25, 7.0, 0, 0}), -175.0);
  // Each leg in contact adds 10; the angular velocity does not count.
  EXPECT_DOUBLE_EQ(LunarLander::Shaping({0.3, 0.4, 0.6, -0.8, -0.25, 0.0, 1, 0}), -165.0);
  EXPECT_DOUBLE_EQ(LunarLander::Shaping({0.3, 0.4, 0.6, -0.8, -0.25, 0.0, 1, 1}), -155.0);
  EXPECT_DOUBLE_EQ(LunarLander::Shaping({0, 0, 0, 0, 0, 0, 0, 0}), 0.0);
  // The reward between two states is the difference of their shapings: from 0.5 away, moving
  // at 0.5, tilted 0.1 (-110) to resting on both legs 0.3 away, level (-30 + 20 = -10): +100.
  const State before = {0.0, 0.5, 0.3, -0.4, 0.1, 0, 0, 0};
  const State after = {0.0, 0.3, 0.0, 0.0, 0.0, 0, 1, 1};
  EXPECT_DOUBLE_EQ(LunarLander::Shaping(before), -110.0);
  EXPECT_DOUBLE_EQ(LunarLander::Shaping(after), -10.0);
  EXPECT_NEAR(LunarLander::Shaping(after) - LunarLander::Shaping(before), 100.0, 1e-12);
}

TEST(LunarLanderTest, CrashOrLeavingTheViewportGivesMinus100AndRestGivesPlus100) {
  const StepResult flying = LunarLander::ApplyTerminationRules(-1.5, false, 0.99, true);
  EXPECT_FALSE(flying.terminated);
  EXPECT_EQ(flying.reward, -1.5);
  EXPECT_FALSE(flying.truncated);

  const StepResult crash = LunarLander::ApplyTerminationRules(12.0, true, 0.0, true);
  EXPECT_TRUE(crash.terminated);
  EXPECT_EQ(crash.reward, -100.0);

  // |s0| >= 1 is out, on either side; exactly 1 counts.
  for (double s0 : {1.0, -1.0, 1.5}) {
    const StepResult out = LunarLander::ApplyTerminationRules(3.0, false, s0, true);
    EXPECT_TRUE(out.terminated) << s0;
    EXPECT_EQ(out.reward, -100.0) << s0;
  }
  EXPECT_FALSE(
      LunarLander::ApplyTerminationRules(3.0, false, std::nextafter(1.0, 0.0), true).terminated);

  const StepResult rest = LunarLander::ApplyTerminationRules(-0.2, false, 0.1, false);
  EXPECT_TRUE(rest.terminated);
  EXPECT_EQ(rest.reward, 100.0);
  // The rest rule is applied last and wins.
  const StepResult both = LunarLander::ApplyTerminationRules(-0.2, true, 1.2, false);
  EXPECT_TRUE(both.terminated);
  EXPECT_EQ(both.reward, 100.0);
}

TEST(LunarLanderTest, RewardIsTheShapingDifferenceMinusFuelForEachDiscreteAction) {
  // Main engine 0.3 per step, side engines 0.03, noop nothing.
  const std::array<double, 4> fuel = {0.0, 0.03, 0.3, 0.03};
  LunarLander env;
  env.Reset(11);
  int checked = 0;
  for (int t = 0; t < 120; ++t) {
    const int action = (t / 3) % 4;
    const double before = ReferenceShaping(env.state());
    const StepResult r = env.Step(DiscreteAction(action));
    if (r.terminated) break;
    const double after = ReferenceShaping(env.state());
    EXPECT_NEAR(r.reward, after - before - fuel[action], 1e-9)
        << "step " << t << " action " << action;
    ++checked;
  }
  EXPECT_GT(checked, 60);
}

TEST(LunarLanderTest, ContinuousThrottlesFollowTheClippingAndDeadZones) {
  struct Case {
    std::array<float, 2> action;
    double m_power;  // Expected main throttle.
    double s_power;  // Expected side throttle.
  };
  const float inf = std::numeric_limits<float>::infinity();
  const std::vector<Case> cases = {
      {{0.0f, 0.0f}, 0.0, 0.0},
      {{-1.0f, 0.5f}, 0.0, 0.0},   // main <= 0 is off; |lateral| = 0.5 is still in the dead zone.
      {{0.5f, -0.5f}, 0.75, 0.0},  // (0.5 + 1) / 2.
      {{1e-3f, 0.0f}, (static_cast<double>(1e-3f) + 1) / 2, 0.0},  // Any positive main fires.
      {{2.0f, -3.0f}, 1.0, 1.0},                                   // Clipped to [-1, 1].
      {{-0.2f, 0.75f}, 0.0, 0.75},
      {{0.0f, -0.51f}, 0.0, static_cast<double>(0.51f)},
      {{inf, -inf}, 1.0, 1.0},
  };
  LunarLander env = ContinuousLander();
  env.Reset(5);
  for (const Case& c : cases) {
    env.SetLanderKinematics(LanderKinematics{.x = 10, .y = 9});
    const double before = ReferenceShaping(env.state());
    const StepResult r = env.Step(c.action);
    ASSERT_FALSE(r.terminated);
    const double fuel = ReferenceShaping(env.state()) - before - r.reward;
    EXPECT_NEAR(fuel, 0.3 * c.m_power + 0.03 * c.s_power, 1e-9)
        << "action (" << c.action[0] << ", " << c.action[1] << ")";
  }
}

// Steps two identically seeded landers, one with `action`, one with noop (the dispersion draws
// are the same, so only the engine differs), and returns the differences (action minus noop) of
// vertical velocity and angular velocity after one step.
struct EngineEffect {
  double dvy;
  double domega;
};
EngineEffect DiscreteEngineEffect(int action) {
  LunarLander fired;
  LunarLander idle;
  fired.Reset(21);
  idle.Reset(21);
  fired.Step(DiscreteAction(action));
  idle.Step(DiscreteAction(0));
  return {fired.lander_kinematics().vy - idle.lander_kinematics().vy,
          fired.lander_kinematics().angular_velocity - idle.lander_kinematics().angular_velocity};
}
EngineEffect ContinuousEngineEffect(std::array<float, 2> action) {
  LunarLander fired = ContinuousLander();
  LunarLander idle = ContinuousLander();
  fired.Reset(21);
  idle.Reset(21);
  fired.Step(action);
  idle.Step(std::array<float, 2>{0, 0});
  return {fired.lander_kinematics().vy - idle.lander_kinematics().vy,
          fired.lander_kinematics().angular_velocity - idle.lander_kinematics().angular_velocity};
}

TEST(LunarLanderTest, EnginesPushInTheDocumentedDirections) {
  // The main engine pushes up: 13 * (4/30 + 2 d0) N s with d0 in [-1/30, 1/30] on about 4.96 kg,
  // between 0.17 and 0.52 m/s.
  const EngineEffect main = DiscreteEngineEffect(2);
  EXPECT_GT(main.dvy, 0.15);
  EXPECT_LT(main.dvy, 0.55);
  // The left engine (1) turns counter-clockwise, the right one (3) clockwise.
  EXPECT_GT(DiscreteEngineEffect(1).domega, 0.01);
  EXPECT_LT(DiscreteEngineEffect(3).domega, -0.01);
  // Continuous: lateral < -0.5 is the left engine, > 0.5 the right one; half throttle on the main
  // engine gives half the push of full throttle.
  EXPECT_GT(ContinuousEngineEffect({0, -1}).domega, 0.01);
  EXPECT_LT(ContinuousEngineEffect({0, 1}).domega, -0.01);
  EXPECT_EQ(ContinuousEngineEffect({0, 0.5f}).domega, 0.0);
  const double full = ContinuousEngineEffect({1, 0}).dvy;
  const double half = ContinuousEngineEffect({0.001f, 0}).dvy;
  EXPECT_NEAR(full, main.dvy, 1e-6);
  EXPECT_NEAR(half / full, 0.5, 0.01);
}

TEST(LunarLanderTest, UpsideDownTouchdownIsACrash) {
  LunarLander env;
  env.Reset(8);
  // Upside down, the top of the hull 1 cm above the pad, falling at 2 m/s.
  env.SetLanderKinematics(LanderKinematics{
      .x = 10, .y = PadHeight(env) + 17.0 / 30 + 0.01, .vy = -2, .angle = std::numbers::pi});
  EXPECT_FALSE(env.game_over());
  StepResult r;
  int steps = 0;
  do {
    r = env.Step(DiscreteAction(0));
    ++steps;
  } while (!r.terminated && steps < 50);
  EXPECT_TRUE(r.terminated);
  EXPECT_EQ(r.reward, -100.0);
  EXPECT_TRUE(env.game_over());
  EXPECT_LE(steps, 3);
}

TEST(LunarLanderTest, LeavingTheViewportSidewaysEndsTheEpisode) {
  for (double x : {20.5, -0.5, 0.0, 20.0}) {
    LunarLander env;
    env.Reset(2);
    env.SetLanderKinematics(LanderKinematics{.x = x, .y = 9});
    const StepResult r = env.Step(DiscreteAction(0));
    EXPECT_TRUE(r.terminated) << "x = " << x;
    EXPECT_EQ(r.reward, -100.0) << "x = " << x;
    EXPECT_FALSE(env.game_over());
  }
  for (double x : {0.5, 19.5}) {
    LunarLander env;
    env.Reset(2);
    env.SetLanderKinematics(LanderKinematics{.x = x, .y = 9});
    EXPECT_FALSE(env.Step(DiscreteAction(0)).terminated) << "x = " << x;
  }
}

TEST(LunarLanderTest, LandingOnThePadEarnsTheLegBonusesAndRestingEndsWithPlus100) {
  LunarLander env;
  env.Reset(4);
  PlaceAbovePad(env);
  bool saw_touchdown = false;
  StepResult r;
  int steps = 0;
  do {
    const double before = ReferenceShaping(env.state());
    const bool had_contact = env.state()[6] != 0 || env.state()[7] != 0;
    r = env.Step(DiscreteAction(0));
    ++steps;
    if (r.terminated) break;
    // The step's reward includes +10 for each leg that came into contact.
    EXPECT_NEAR(r.reward, ReferenceShaping(env.state()) - before, 1e-9) << "step " << steps;
    if (!had_contact && env.state()[6] == 1 && env.state()[7] == 1) saw_touchdown = true;
  } while (steps < 500);
  EXPECT_TRUE(saw_touchdown);
  EXPECT_TRUE(r.terminated);
  EXPECT_EQ(r.reward, 100.0);
  EXPECT_FALSE(env.lander_awake());
  EXPECT_FALSE(env.game_over());
  EXPECT_TRUE(env.leg_ground_contact(0));
  EXPECT_TRUE(env.leg_ground_contact(1));
  EXPECT_EQ(env.observation()[6], 1.0f);
  EXPECT_EQ(env.observation()[7], 1.0f);
  // Resting on the pad centre, level and still: the observation is near the origin.
  EXPECT_NEAR(env.observation()[0], 0.0f, 0.01f);
  EXPECT_NEAR(env.observation()[1], 0.0f, 0.05f);
  EXPECT_EQ(env.observation()[2], 0.0f);  // Sleeping zeroes the velocities.
  EXPECT_EQ(env.observation()[3], 0.0f);
  // Box2D needs 0.5 s (25 steps) of rest before it puts the body to sleep.
  EXPECT_GE(steps, 25);
}

TEST(LunarLanderTest, ResetBuildsTheDocumentedTerrainAndStartsInTheAirAtTheTop) {
  LunarLander env;
  env.Reset(17);
  for (int i = 0; i < LunarLander::kChunks; ++i) {
    EXPECT_EQ(env.terrain_x()[i], 2.0 * i);
    EXPECT_GE(env.terrain_y()[i], 0.0);
    EXPECT_LE(env.terrain_y()[i], 0.99 * LunarLander::kH / 2);
  }
  // The pad: points 4, 5 and 6 are at 0.33 * 3 * helipad_y.
  for (int i = 4; i <= 6; ++i) EXPECT_DOUBLE_EQ(env.terrain_y()[i], 0.99 * LunarLander::kH / 4);
  // Points 3 and 7 average the pad with one random neighbour, so they differ from it.
  EXPECT_NE(env.terrain_y()[3], env.terrain_y()[4]);
  // One real step has been taken from (10, H): the lander is near the top centre, not in contact.
  const LanderKinematics k = env.lander_kinematics();
  EXPECT_NEAR(k.x, 10.0, 0.1);
  EXPECT_NEAR(k.y, LunarLander::kH, 0.1);
  EXPECT_NEAR(env.observation()[1],
              (LunarLander::kH - LunarLander::kH / 4 - 0.6) / (LunarLander::kH / 2), 0.02);
  EXPECT_EQ(env.observation()[6], 0.0f);
  EXPECT_EQ(env.observation()[7], 0.0f);
  EXPECT_FALSE(env.game_over());
  EXPECT_TRUE(env.lander_awake());
  // The initial force gives up to 20 N s per axis to about 4.96 kg: at most ~4 m/s.
  EXPECT_LE(std::abs(k.vx), 4.2);
  EXPECT_LE(std::abs(k.vy - (-10.0 / 50)), 4.2);
}

TEST(LunarLanderTest, InitialForceIsRandomInBothDirections) {
  LunarLander env;
  int left = 0;
  int right = 0;
  double max_speed = 0;
  for (uint64_t seed = 0; seed < 60; ++seed) {
    env.Reset(seed);
    const double vx = env.lander_kinematics().vx;
    left += vx < 0;
    right += vx > 0;
    max_speed = std::max(max_speed, std::abs(vx));
  }
  EXPECT_GT(left, 15);
  EXPECT_GT(right, 15);
  EXPECT_GT(max_speed, 2.5);  // Forces reach +-1000 N: about 4 m/s after one step.
}

TEST(LunarLanderTest, LegsHangOnTheirSidesAtTheInnerJointLimitsInFlight) {
  LunarLander env;
  env.Reset(9);
  for (int t = 0; t < 25; ++t) env.Step(DiscreteAction(0));
  ASSERT_GT(env.lander_kinematics().y, 8.0);  // Still falling freely.
  // Limits: leg 0 in [0.4, 0.9], leg 1 in [-0.9, -0.4]; the motors push to the inner ends.
  EXPECT_NEAR(env.leg_joint_angle(0), 0.4, 0.05);
  EXPECT_NEAR(env.leg_joint_angle(1), -0.4, 0.05);
  // Leg 0 hangs on the +x side of the lander, leg 1 on the -x side, both below its origin.
  const LanderKinematics k = env.lander_kinematics();
  const auto polygons = env.body_polygons();
  ASSERT_EQ(polygons.size(), 3u);
  const double c = std::cos(k.angle);
  const double s = std::sin(k.angle);
  for (int leg = 0; leg < 2; ++leg) {
    ASSERT_EQ(polygons[leg + 1].size(), 4u);
    double mean_x = 0;
    double mean_y = 0;
    for (const auto& v : polygons[leg + 1]) {
      // In the lander's frame.
      mean_x += (c * (v[0] - k.x) + s * (v[1] - k.y)) / 4;
      mean_y += (-s * (v[0] - k.x) + c * (v[1] - k.y)) / 4;
    }
    EXPECT_NEAR(mean_x, leg == 0 ? 0.83 : -0.83, 0.1) << "leg " << leg;
    EXPECT_NEAR(mean_y, -0.33, 0.1) << "leg " << leg;
  }
  EXPECT_EQ(polygons[0].size(), 6u);  // The hull.
}

TEST(LunarLanderTest, SameSeedAndActionsGiveBitIdenticalEpisodes) {
  const std::vector<float> a = RandomEpisode(42, 7);
  const std::vector<float> b = RandomEpisode(42, 7);
  ASSERT_GT(a.size(), 8u * 30u);
  ASSERT_EQ(a.size(), b.size());
  EXPECT_EQ(std::memcmp(a.data(), b.data(), a.size() * sizeof(float)), 0);

  // A second episode from the same seed on the same instance repeats the first (a new world).
  LunarLander env;
  TrajectoryHash first;
  TrajectoryHash second;
  for (TrajectoryHash* hash : {&first, &second}) {
    env.Reset(99);
    for (int t = 0; t < 300; ++t) {
      const StepResult r = env.Step(DiscreteAction(t % 7 == 0 ? 2 : t % 4));
      for (float v : env.observation()) hash->Add(v);
      hash->Add(r.reward);
      if (r.terminated) break;
    }
  }
  EXPECT_EQ(first.value(), second.value());
}

TEST(LunarLanderTest, DifferentSeedsGiveDifferentTerrainAndInitialPush) {
  LunarLander a;
  LunarLander b;
  LunarLander c;
  a.Reset(1);
  b.Reset(2);
  c.Reset(1 + (uint64_t{1} << 32));  // Differs only in the high 32 bits.
  EXPECT_NE(a.terrain_y(), b.terrain_y());
  EXPECT_NE(a.terrain_y(), c.terrain_y());
  EXPECT_NE(a.lander_kinematics().vx, b.lander_kinematics().vx);
  EXPECT_NE(RandomEpisode(1, 7), RandomEpisode(2, 7));

  // Reset() without a seed continues the stream: a new terrain.
  const std::array<double, LunarLander::kChunks> first = a.terrain_y();
  a.Reset();
  EXPECT_NE(a.terrain_y(), first);
}

TEST(LunarLanderTest, EveryStepDrawsTwoDispersionValuesWhetherOrNotAnEngineFires) {
  // The terrain of the next unseeded Reset reveals how far the RNG stream has advanced.
  const auto terrain_after = [](const std::vector<int>& actions) {
    LunarLander env;
    env.Reset(31);
    for (int a : actions) env.Step(DiscreteAction(a));
    env.Reset();
    return env.terrain_y();
  };
  const auto idle = terrain_after({0, 0, 0, 0, 0});
  EXPECT_EQ(terrain_after({2, 2, 2, 2, 2}), idle);
  EXPECT_EQ(terrain_after({1, 3, 2, 0, 3}), idle);
  EXPECT_NE(terrain_after({0, 0, 0, 0}), idle);
}

TEST(LunarLanderTest, WindMagnitudeFollowsTheTanhOfTwoSines) {
  EXPECT_EQ(LunarLander::WindMagnitude(0, 15.0), 0.0);
  // tanh(sin(1) + sin(pi / 2)), printed by python3.
  EXPECT_NEAR(LunarLander::WindMagnitude(50, 1.0), 0.950936143654817, 1e-15);
  EXPECT_NEAR(LunarLander::WindMagnitude(-120, 15.0), -1.3118091697340288, 1e-14);
  for (int64_t i = -9999; i < 9999; i += 37) {
    ASSERT_LE(std::abs(LunarLander::WindMagnitude(i, 2.0)), 2.0);
  }
}

TEST(LunarLanderTest, WindPushesTheLanderAndAdvancesOncePerStepInFlight) {
  // Same seed, same RNG draws (both draw the wind phases); only the wind force differs.
  LunarLander calm(LunarLanderConfig{.enable_wind = true, .wind_power = 0, .turbulence_power = 0});
  LunarLander windy(
      LunarLanderConfig{.enable_wind = true, .wind_power = 20, .turbulence_power = 0});
  calm.Reset(6);
  windy.Reset(6);
  EXPECT_EQ(calm.wind_index(), windy.wind_index());
  EXPECT_GE(windy.wind_index(), -9999 + 1);  // Drawn in [-9999, 9999), then one step.
  EXPECT_LE(windy.wind_index(), 9999);
  // The step inside Reset already blew once, with the phase before the current one.
  double impulse = LunarLander::WindMagnitude(windy.wind_index() - 1, 20.0) / LunarLander::kFps;
  for (int t = 0; t < 30; ++t) {
    impulse += LunarLander::WindMagnitude(windy.wind_index(), 20.0) / LunarLander::kFps;
    const int64_t index = windy.wind_index();
    const int64_t torque_index = windy.torque_index();
    calm.Step(DiscreteAction(0));
    windy.Step(DiscreteAction(0));
    EXPECT_EQ(windy.wind_index(), index + 1);
    EXPECT_EQ(windy.torque_index(), torque_index + 1);
  }
  ASSERT_GT(std::abs(impulse), 1.0);
  // The wind's momentum spreads over the whole craft (about 4.96 kg).
  const double dvx = windy.lander_kinematics().vx - calm.lander_kinematics().vx;
  EXPECT_NEAR(dvx, impulse / 4.959, std::abs(impulse / 4.959) * 0.2);

  // Without enable_wind the phases stay 0 and draw nothing.
  LunarLander plain;
  plain.Reset(6);
  plain.Step(DiscreteAction(0));
  EXPECT_EQ(plain.wind_index(), 0);
  EXPECT_EQ(plain.torque_index(), 0);
}

TEST(LunarLanderTest, WindStopsOnceALegTouches) {
  LunarLander env(LunarLanderConfig{.enable_wind = true});
  env.Reset(4);
  PlaceAbovePad(env);
  int64_t index = env.wind_index();
  bool touched = false;
  for (int t = 0; t < 60 && !touched; ++t) {
    const bool contact = env.leg_ground_contact(0) || env.leg_ground_contact(1);
    env.Step(DiscreteAction(0));
    EXPECT_EQ(env.wind_index(), contact ? index : index + 1) << "step " << t;
    index = env.wind_index();
    touched = contact;
  }
  EXPECT_TRUE(touched);
}

TEST(LunarLanderTest, InvalidCallsThrowAndLeaveTheEpisodeUnchanged) {
  LunarLander env;
  EXPECT_THROW(env.Step(DiscreteAction(0)), std::logic_error);
  std::vector<uint8_t> rgb;
  int width = 0;
  int height = 0;
  EXPECT_THROW(env.Render(&rgb, &width, &height), std::logic_error);
  EXPECT_THROW(env.SetLanderKinematics({}), std::logic_error);

  // A bad action neither moves the lander nor consumes randomness: the twin stays in step.
  LunarLander twin;
  env.Reset(3);
  twin.Reset(3);
  EXPECT_THROW(env.Step(DiscreteAction(4)), std::invalid_argument);
  EXPECT_THROW(env.Step(DiscreteAction(-1)), std::invalid_argument);
  EXPECT_THROW(env.Step(std::array<float, 1>{1.5f}), std::invalid_argument);
  try {
    env.Step(DiscreteAction(7));
    FAIL() << "expected std::invalid_argument";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find('7'), std::string::npos) << e.what();
  }
  env.Step(DiscreteAction(2));
  twin.Step(DiscreteAction(2));
  for (int i = 0; i < 8; ++i) EXPECT_EQ(env.observation()[i], twin.observation()[i]) << i;

  // Each variant refuses the other's actions: a discrete action is one float, a continuous two.
  try {
    env.Step(std::array<float, 2>{0, 0});
    FAIL() << "expected std::invalid_argument";
  } catch (const std::invalid_argument& e) {
    EXPECT_EQ(std::string(e.what()), "LunarLander-v3: action of the wrong width (got [0, 0])");
  }
  LunarLander continuous = ContinuousLander();
  EXPECT_THROW(continuous.Step(std::array<float, 2>{0, 0}), std::logic_error);
  continuous.Reset(3);
  EXPECT_THROW(continuous.Step(DiscreteAction(0)), std::invalid_argument);
  EXPECT_THROW(continuous.Step(std::array<float, 1>{0}), std::invalid_argument);
  EXPECT_THROW(continuous.Step(std::array<float, 3>{0, 0, 0}), std::invalid_argument);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  EXPECT_THROW(continuous.Step(std::array<float, 2>{nan, 0}), std::invalid_argument);
  EXPECT_THROW(continuous.Step(std::array<float, 2>{0, nan}), std::invalid_argument);
}

TEST(LunarLanderTest, TimeLimitTruncatesAHoveringLanderAtStep1000) {
  auto env = MakeEnv("LunarLander-v3");
  auto& limit = dynamic_cast<TimeLimit&>(*env);
  auto& lander = dynamic_cast<LunarLander&>(limit.wrapped_env());
  env->Reset(12);
  // Hold the lander still in mid-air before every step, so that it neither lands nor sleeps.
  for (int t = 1; t <= 999; ++t) {
    lander.SetLanderKinematics(LanderKinematics{.x = 10, .y = 9});
    const StepResult r = env->Step(DiscreteAction(t % 4));
    ASSERT_FALSE(r.terminated) << "step " << t;
    ASSERT_FALSE(r.truncated) << "step " << t;
  }
  lander.SetLanderKinematics(LanderKinematics{.x = 10, .y = 9});
  const StepResult last = env->Step(DiscreteAction(0));
  EXPECT_TRUE(last.truncated);
  EXPECT_FALSE(last.terminated);
  EXPECT_EQ(limit.elapsed_steps(), 1000);
}

TEST(LunarLanderTest, TimeLimitCountsContinuousStepsAndRejectsThemOnTheDiscreteVariant) {
  auto continuous = MakeEnv("LunarLanderContinuous-v3");
  continuous->Reset(1);
  continuous->Step(std::array<float, 2>{0.5f, 0.0f});
  continuous->Step(std::array<float, 2>{0.0f, -1.0f});
  EXPECT_EQ(dynamic_cast<TimeLimit&>(*continuous).elapsed_steps(), 2);
  EXPECT_THROW(continuous->Step(std::array<float, 1>{0}), std::invalid_argument);
  EXPECT_EQ(dynamic_cast<TimeLimit&>(*continuous).elapsed_steps(), 2);

  auto discrete = MakeEnv("LunarLander-v3");
  discrete->Reset(1);
  EXPECT_THROW(discrete->Step(std::array<float, 2>{0, 0}), std::invalid_argument);
  EXPECT_EQ(dynamic_cast<TimeLimit&>(*discrete).elapsed_steps(), 0);
}

TEST(LunarLanderTest, MovedLanderKeepsItsLegsAttached) {
  LunarLander env;
  env.Reset(5);
  const double angle0 = env.leg_joint_angle(0);
  const double angle1 = env.leg_joint_angle(1);
  env.SetLanderKinematics(LanderKinematics{.x = 4, .y = 10, .angle = 1.0, .angular_velocity = 0});
  // The joints are where they were: same joint angles, same anchors.
  EXPECT_NEAR(env.leg_joint_angle(0), angle0, 1e-5);
  EXPECT_NEAR(env.leg_joint_angle(1), angle1, 1e-5);
  env.Step(DiscreteAction(0));
  EXPECT_NEAR(env.leg_joint_angle(0), angle0, 0.05);
  EXPECT_NEAR(env.lander_kinematics().x, 4.0, 0.01);
}

}  // namespace
}  // namespace rl::envs
