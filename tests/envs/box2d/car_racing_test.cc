// CarRacing (environments.md 3): the car's tyre model against hand-computed values, the reward
// and episode rules, the reference's validation numbers, determinism, refusals, and what the
// pictures show.
#include "envs/box2d/car_racing.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <random>
#include <stdexcept>
#include <vector>

#include "envs/box2d/car_racing_pilot.h"
#include "envs/image/image_source.h"
#include "envs/pixel_spec.h"
#include "envs/registry.h"
#include "envs/specs.h"
#include "envs/wrapper.h"
#include "tests/envs/image_testing.h"

namespace rl::envs {
namespace {

constexpr double kDt = 0.02;

StepResult Drive(CarRacing& env, float steer, float gas, float brake) {
  const std::array<float, 3> action = {steer, gas, brake};
  return env.Step(action);
}

// Mean summed reward of a fixed action held for 100 steps, over 100 tracks.
double FixedActionScore(std::array<float, 3> action) {
  double sum = 0;
  for (uint64_t seed = 0; seed < 100; ++seed) {
    CarRacing env;
    env.Reset(1000 + seed);
    for (int k = 0; k < 100; ++k) {
      const StepResult r = env.Step(action);
      sum += r.reward;
      if (r.terminated) break;
    }
  }
  return sum / 100;
}

TEST(CarRacingTest, FixedActionScoresMatchTheReferencesValidationNumbers) {
  // envpool's box2d_correctness_test: the reference's mean over 100 envs, +-1 there. Tracks here
  // come from other random numbers (car_racing.cc), so the bound is wider.
  EXPECT_NEAR(FixedActionScore({0.0f, 0.5f, 0.0f}), 65.0, 2.5);
  EXPECT_NEAR(FixedActionScore({0.1f, 0.3f, 0.0f}), 18.5, 2.5);
  EXPECT_NEAR(FixedActionScore({0.0f, 0.7f, 0.1f}), 42.7, 2.5);
}

TEST(CarRacingTest, FirstGasStepSlipsTheRearWheelsAtTheFrictionLimit) {
  CarRacing env;
  env.Reset(3);
  Drive(env, 0, 1, 0);
  const CarRacingCar car = env.car();
  for (int k = 2; k < 4; ++k) {
    // Gas rises to 0.1; the engine adds 0.02 * 40000 * 0.1 / 1.6 / 5 = 10 rad/s; the tyre force
    // (5.4 m/s of slip * 82 = 443) is capped at the road's 400, which takes back
    // 0.02 * 400 * 0.54 / 1.6 = 2.7 rad/s.
    ASSERT_GT(car.wheels[k].tiles, 0) << "the car starts on the road";
    EXPECT_NEAR(car.wheels[k].gas, 0.1, 1e-12);
    EXPECT_NEAR(car.wheels[k].omega, 7.3, 0.05) << "wheel " << k;
  }
  // The front wheels are not driven.
  EXPECT_EQ(car.wheels[0].gas, 0);
  EXPECT_NEAR(car.wheels[0].omega, 0, 0.5);
}

TEST(CarRacingTest, FullGasAcceleratesAsTheTyreModelImplies) {
  // A point-mass model of the car going straight: four wheels with the reference's formulas
  // (environments.md 3.8), the hull's and wheels' masses, no steering.
  CarRacing env;
  env.Reset(5);
  const double mass = 7.06 + 4 * 0.06048;
  double v = env.car().speed();
  std::array<double, 4> omega{};
  std::array<double, 4> gas{};
  for (int step = 1; step <= 40; ++step) {
    double force = 0;
    for (int k = 0; k < 4; ++k) {
      if (k >= 2) gas[k] = std::min(gas[k] + 0.1, 1.0);
      omega[k] += kDt * 40000 * gas[k] / 1.6 / (std::abs(omega[k]) + 5);
      const double limit = env.car().wheels[k].tiles > 0 ? 400 : 240;
      const double f = std::clamp((-v + omega[k] * 0.54) * 82, -limit, limit);
      omega[k] -= kDt * f * 0.54 / 1.6;
      force += f;
    }
    v += kDt * force / mass;
    Drive(env, 0, 1, 0);
    if (step % 10 == 0) {
      EXPECT_NEAR(env.car().speed(), v, 0.03 * v) << "step " << step;
      EXPECT_NEAR(env.car().wheels[2].omega, omega[2], 0.03 * omega[2]) << "step " << step;
    }
  }
  EXPECT_GT(v, 30);
}

TEST(CarRacingTest, LockedBrakeStopsTheWheelsAndTheTyresSlipAtTheLimit) {
  CarRacing env;
  env.Reset(9);
  for (int k = 0; k < 30; ++k) Drive(env, 0, 1, 0);
  const double before = env.car().speed();
  ASSERT_GT(before, 20);
  Drive(env, 0, 0, 1);
  const CarRacingCar car = env.car();
  for (int k = 0; k < 4; ++k) {
    // brake >= 0.9 sets omega to 0, then the sliding tyre's capped force turns the wheel forward
    // by 0.02 * limit * 0.54 / 1.6: 2.7 rad/s on the road, 1.62 on grass.
    const double limit = car.wheels[k].tiles > 0 ? 400 : 240;
    EXPECT_NEAR(car.wheels[k].omega, kDt * limit * 0.54 / 1.6, 0.05) << "wheel " << k;
    EXPECT_EQ(car.wheels[k].brake, 1.0);
  }
  // Four tyres at the limit decelerate the car by about 4 * 400 / 7.3 * 0.02 = 4.4 m/s a step.
  EXPECT_NEAR(before - car.speed(), 4 * 400 / 7.3 * kDt, 0.6);
}

// With pedals, [steer, p] drives as [steer, max(p, 0), max(-p, 0)] does: the same car, state for
// state, through gas, coasting and the brake.
TEST(CarRacingTest, PedalsDriveAsGasAndBrakeOfTheSameSign) {
  CarRacing three;
  CarRacing pedals(CarRacingConfig{.pedals = true});
  EXPECT_EQ(pedals.spec().action_dim, 2);
  EXPECT_EQ(pedals.spec().action_low, (std::vector<float>{-1, -1}));
  EXPECT_EQ(pedals.spec().action_high, (std::vector<float>{1, 1}));
  three.Reset(6);
  pedals.Reset(6);
  const std::vector<std::array<float, 2>> plan = {{0, 1},    {0.3f, 0.6f}, {-0.5f, 0}, {0, -0.4f},
                                                  {0.2f, 1}, {0, -1},      {-1, 0.8f}, {0, 2}};
  for (int k = 0; k < 80; ++k) {
    const auto [steer, pedal] = plan[k / 10];
    const StepResult a = Drive(three, steer, std::max(pedal, 0.0f), std::max(-pedal, 0.0f));
    const std::array<float, 2> pressed = {steer, pedal};
    const StepResult b = pedals.Step(pressed);
    ASSERT_EQ(a.reward, b.reward) << "step " << k;
    ASSERT_EQ(a.terminated, b.terminated);
    ASSERT_EQ(three.car().position.x, pedals.car().position.x) << "step " << k;
    ASSERT_EQ(three.car().position.y, pedals.car().position.y);
    ASSERT_EQ(three.car().speed(), pedals.car().speed());
  }
  EXPECT_GT(pedals.car().wheels[2].gas, 0.9);  // the last pedal, 2, clipped to full gas
  EXPECT_EQ(pedals.car().wheels[2].brake, 0);
  const std::array<float, 3> three_wide = {0, 0, 0};
  EXPECT_THROW(pedals.Step(three_wide), std::invalid_argument);
  EXPECT_THROW(CarRacing(CarRacingConfig{.continuous = false, .pedals = true}),
               std::invalid_argument);
}

TEST(CarRacingTest, SteeringTurnsTheFrontWheelsToTheirStopsAndTheCarRight) {
  CarRacing env;
  env.Reset(4);
  for (int k = 0; k < 10; ++k) Drive(env, 0, 0.5f, 0);
  const double angle0 = env.car().angle;
  for (int k = 0; k < 25; ++k) Drive(env, 1, 0.2f, 0);  // Steer right: the joint's target -1.
  const CarRacingCar car = env.car();
  EXPECT_NEAR(car.wheels[0].joint_angle, -0.4, 0.03);
  EXPECT_NEAR(car.wheels[1].joint_angle, -0.4, 0.03);
  EXPECT_NEAR(car.wheels[2].joint_angle, 0, 0.02);
  EXPECT_NEAR(car.wheels[3].joint_angle, 0, 0.02);
  EXPECT_EQ(car.wheels[0].steer, -1);
  EXPECT_EQ(car.wheels[2].steer, 0);
  EXPECT_LT(car.angle, angle0 - 0.2);  // Clockwise.
}

TEST(CarRacingTest, DiscreteActionsSetAllThreeControls) {
  CarRacing env(CarRacingConfig{.continuous = false});
  env.Reset(2);
  env.Step(DiscreteAction(3));
  EXPECT_NEAR(env.car().wheels[2].gas, 0.1, 1e-12);
  env.Step(DiscreteAction(3));
  env.Step(DiscreteAction(3));
  EXPECT_NEAR(env.car().wheels[3].gas, 0.2, 1e-12);  // Gas 0.2, reached in two steps.
  env.Step(DiscreteAction(1));
  EXPECT_EQ(env.car().wheels[0].steer, -0.6);  // Right.
  EXPECT_EQ(env.car().wheels[2].gas, 0);       // Each action sets all three controls.
  env.Step(DiscreteAction(2));
  EXPECT_EQ(env.car().wheels[1].steer, 0.6);
  env.Step(DiscreteAction(4));
  EXPECT_EQ(env.car().wheels[0].brake, 0.8);
  EXPECT_EQ(env.car().wheels[0].steer, 0);
  env.Step(DiscreteAction(0));
  EXPECT_EQ(env.car().wheels[0].brake, 0);
}

TEST(CarRacingTest, ResetStepVisitsTheStartTilesAndTheFirstStepPaysForThem) {
  CarRacing env;
  env.Reset(8);
  const int n = env.track().size();
  EXPECT_DOUBLE_EQ(env.time(), 0.02);
  ASSERT_GE(env.tiles_visited(), 1);
  EXPECT_TRUE(env.tile_visited(0));
  EXPECT_NEAR(env.episode_reward(), env.tiles_visited() * 1000.0 / n, 1e-9);
  const double visited_at_reset = env.episode_reward();
  const int tiles_before = env.tiles_visited();
  const StepResult r = Drive(env, 0, 0, 0);
  const double new_tiles = (env.tiles_visited() - tiles_before) * 1000.0 / n;
  EXPECT_NEAR(r.reward, visited_at_reset + new_tiles - 0.1, 1e-9);
  const StepResult idle = Drive(env, 0, 0, 0);
  EXPECT_NEAR(idle.reward, (env.tiles_visited() - tiles_before) * 1000.0 / n - new_tiles - 0.1,
              1e-9);
}

TEST(CarRacingTest, ALapVisitingEveryTileScoresAThousandLessATenthPerFrame) {
  CarRacing env;
  CarRacingPilot pilot;
  env.Reset(21);
  double sum = 0;
  int frames = 0;
  bool finished = false;
  while (frames < 1000 && !finished) {
    const StepResult r = env.Step(pilot.Act(env));
    sum += r.reward;
    ++frames;
    finished = r.terminated;
  }
  ASSERT_TRUE(env.lap_finished());
  EXPECT_EQ(env.tiles_visited(), env.track().size());
  EXPECT_NEAR(sum, 1000 - 0.1 * frames, 1e-6);
}

// With lap_ends off (the TD3 article's rule), the finished lap ends nothing: the car drives on,
// every further frame costs 0.1 and pays nothing, until the playfield's edge or a time limit.
TEST(CarRacingTest, WithoutLapEndsTheCarDrivesOnPastAFinishedLap) {
  CarRacing env(CarRacingConfig{.lap_ends = false});
  CarRacingPilot pilot;
  env.Reset(21);
  double sum = 0;
  int frames = 0;
  while (env.tiles_visited() < env.track().size()) {
    ASSERT_LT(frames, 1000);
    const StepResult r = env.Step(pilot.Act(env));
    ASSERT_FALSE(r.terminated);
    sum += r.reward;
    ++frames;
  }
  EXPECT_NEAR(sum, 1000 - 0.1 * frames, 1e-6);
  for (int k = 0; k < 50; ++k) {
    const StepResult r = env.Step(pilot.Act(env));
    EXPECT_FALSE(r.terminated);
    EXPECT_FALSE(env.lap_finished());
    EXPECT_NEAR(r.reward, -0.1, 1e-9);
  }
}

// Whether the picture shows grass (green above 200) at row 75 and columns 41, 42, 52 and 53.
bool ShowsGrassBesideTheCar(const CarRacing& env) {
  std::vector<uint8_t> rgb;
  int width = 0;
  int height = 0;
  env.Render(&rgb, &width, &height);
  for (int column : {41, 42, 52, 53}) {
    if (rgb[static_cast<std::size_t>((75 * width + column) * 3 + 1)] <= 200) return false;
  }
  return true;
}

// The off-track rule, against a twin without it on the same seed and actions: each step pays the
// twin's reward until the step past off_track_after whose picture shows grass on both sides of
// the car for the (grace + 1)-th frame in a row, which pays -10 and ends the episode.
void CheckOffTrackRule(int after, int grace = 0) {
  CarRacing env(
      CarRacingConfig{.off_track = true, .off_track_after = after, .off_track_grace = grace});
  CarRacing twin;
  env.Reset(4);
  twin.Reset(4);
  const std::array<float, 3> swerve = {1.0f, 0.5f, 0.0f};  // Full right: off the road soon.
  bool ended = false;
  bool skipped_grass = false;
  int in_a_row = 0;
  int most_in_a_row = 0;
  for (int t = 1; t <= 400 && !ended; ++t) {
    const StepResult r = env.Step(swerve);
    const StepResult plain = twin.Step(swerve);
    const bool grass = ShowsGrassBesideTheCar(twin);
    if (grass && t <= after) skipped_grass = true;
    in_a_row = grass && t > after ? in_a_row + 1 : 0;
    most_in_a_row = std::max(most_in_a_row, in_a_row);
    if (in_a_row > grace) {
      EXPECT_EQ(r.reward, -10.0) << "step " << t;
      EXPECT_TRUE(r.terminated) << "step " << t;
      ended = true;
    } else {
      ASSERT_EQ(r.reward, plain.reward) << "step " << t;
      ASSERT_EQ(r.terminated, plain.terminated) << "step " << t;
    }
  }
  EXPECT_TRUE(ended) << "the car never left the road";
  EXPECT_EQ(most_in_a_row, grace + 1);
  if (after > 0) {
    EXPECT_TRUE(skipped_grass) << "nothing for off_track_after to skip";
  }
}

TEST(CarRacingTest, OffTrackRuleEndsTheEpisodeOnTheFirstFrameOnGrass) { CheckOffTrackRule(0); }

TEST(CarRacingTest, OffTrackRuleSkipsTheFirstFramesOfAnEpisode) {
  // During the zoom-in the picture shows grass beside the car: the article's 45 no-op frames.
  CheckOffTrackRule(45);
}

TEST(CarRacingTest, OffTrackRuleWithAGraceEndsTheEpisodeAfterThatManyFramesOnGrassInARow) {
  CheckOffTrackRule(45, 30);
  CarRacingConfig bad{.off_track = true, .off_track_grace = -1};
  EXPECT_THROW(bad.Validate(), std::invalid_argument);
}

// The pixels keys off-track and lap-ends reach CarRacing's own options; the rule skips the
// no-op frames of the id.
TEST(CarRacingTest, EnvIdKeysSetTheRulesOfTheEnvUnderThePipeline) {
  auto env = MakeEnv("CarRacing-v3+pixels(skip=5,noop-start=45,off-track=1,lap-ends=0)");
  // ClipReward is off: the pipeline is FrameStack > FrameProcessor > ActionRepeat > TimeLimit.
  const Env* inner = env.get();
  const CarRacing* car = nullptr;
  for (int depth = 0; depth < 6 && car == nullptr; ++depth) {
    car = dynamic_cast<const CarRacing*>(inner);
    if (const auto* w = dynamic_cast<const EnvWrapper<ImageSource, ImageSource>*>(inner)) {
      inner = &w->wrapped_env();
    } else if (const auto* e = dynamic_cast<const EnvWrapper<Env, ImageSource>*>(inner)) {
      inner = &e->wrapped_env();
    } else if (const auto* i = dynamic_cast<const EnvWrapper<ImageSource, Env>*>(inner)) {
      inner = &i->wrapped_env();
    } else if (const auto* p = dynamic_cast<const EnvWrapper<Env, Env>*>(inner)) {
      inner = &p->wrapped_env();
    }
  }
  ASSERT_NE(car, nullptr);
  EXPECT_TRUE(car->config().off_track);
  EXPECT_EQ(car->config().off_track_after, 45);
  EXPECT_FALSE(car->config().lap_ends);
  EXPECT_EQ(car->config().off_track_grace, 0);
  EXPECT_FALSE(ParseEnvId("CarRacing-v3+pixels(skip=5)").off_track);
  EXPECT_EQ(ParseEnvId("CarRacing-v3+pixels(off-track=1,off-track-grace=50)").off_track_grace, 50);
  EXPECT_FALSE(car->config().pedals);
  const auto pedals = MakeEnv("CarRacing-v3+pixels(skip=5,pedals=1)");
  EXPECT_EQ(pedals->spec().action_dim, 2);
  EXPECT_TRUE(SameShape(pedals->spec(), LookupSpec("CarRacing-v3+pixels(skip=5,pedals=1)")));
  EXPECT_FALSE(SameShape(pedals->spec(), LookupSpec("CarRacing-v3+pixels(skip=5)")));
}

// The scripted pilot on `tracks` tracks (seeds 5000 on), deciding every frame, each episode ended
// at 1,000 frames as MakeEnv's TimeLimit ends them: its mean return and the laps finished.
struct PilotResult {
  double mean = 0;
  int laps = 0;
};
PilotResult DrivePilot(bool discrete, int tracks) {
  PilotResult result;
  for (int seed = 0; seed < tracks; ++seed) {
    CarRacing env(CarRacingConfig{.continuous = !discrete});
    CarRacingPilot pilot;
    env.Reset(5000 + seed);
    for (int frame = 0; frame < 1000; ++frame) {
      const StepResult r =
          discrete ? env.Step(DiscreteAction(pilot.ActDiscrete(env))) : env.Step(pilot.Act(env));
      result.mean += r.reward / tracks;
      if (r.terminated) break;
    }
    result.laps += env.lap_finished();
  }
  return result;
}

TEST(CarRacingTest, ScriptedPilotCompletesLapsWithAHighScore) {
  // Thirty tracks here (bench/ reports 100): the env is drivable and its reward right.
  const PilotResult pilot = DrivePilot(/*discrete=*/false, 30);
  EXPECT_GE(pilot.laps, 28);
  EXPECT_GT(pilot.mean, 880);
}

TEST(CarRacingTest, ScriptedPilotDrivesTheDiscreteVariant) {
  // The five actions (gas 0.2, steering without gas) can finish a lap: ten tracks here (bench/
  // reports 100, deciding every frame and every fifth as the presets decide).
  const PilotResult pilot = DrivePilot(/*discrete=*/true, 10);
  EXPECT_GE(pilot.laps, 4);
  EXPECT_GT(pilot.mean, 850);
}

TEST(CarRacingTest, LeavingThePlayfieldCostsAHundredAndEndsTheEpisode) {
  CarRacing env;
  env.Reset(6);
  StepResult r;
  int steps = 0;
  do {
    r = Drive(env, 0, 1, 0);  // Straight ahead at full gas, off the road and out.
  } while (!r.terminated && ++steps < 2000);
  ASSERT_TRUE(r.terminated);
  EXPECT_EQ(r.reward, -100);
  EXPECT_FALSE(env.lap_finished());
  const CarRacingCar car = env.car();
  EXPECT_GT(std::max(std::abs(car.position.x), std::abs(car.position.y)),
            CarRacingTrack::kPlayfield);
}

TEST(CarRacingTest, RandomPolicyScoresBelowZero) {
  std::mt19937 rng(1);
  std::uniform_real_distribution<float> unit(0, 1);
  double total = 0;
  for (uint64_t seed = 0; seed < 5; ++seed) {
    CarRacing env;
    env.Reset(300 + seed);
    for (int k = 0; k < 1000; ++k) {
      const StepResult r = Drive(env, 2 * unit(rng) - 1, unit(rng), unit(rng));
      total += r.reward;
      if (r.terminated) break;
    }
  }
  EXPECT_LT(total / 5, 0);
}

TEST(CarRacingTest, SameSeedAndActionsGiveTheSameEpisodeAndPictures) {
  CarRacing a;
  CarRacing b;
  a.Reset(77);
  b.Reset(77);
  for (int k = 0; k < 120; ++k) {
    const float steer = static_cast<float>(std::sin(k * 0.1));
    const StepResult ra = Drive(a, steer, 0.6f, 0);
    const StepResult rb = Drive(b, steer, 0.6f, 0);
    ASSERT_EQ(ra.reward, rb.reward);
  }
  const auto oa = a.observation();
  const auto ob = b.observation();
  ASSERT_TRUE(std::equal(oa.begin(), oa.end(), ob.begin(), ob.end()));
  CarRacing c;
  c.Reset(78);
  EXPECT_NE(c.track().size() * 1000 + c.track().nodes[5].x,
            a.track().size() * 1000 + a.track().nodes[5].x);
}

TEST(CarRacingTest, BadActionsAndCallsBeforeResetAreRefused) {
  CarRacing continuous;
  EXPECT_THROW(Drive(continuous, 0, 0, 0), std::logic_error);
  EXPECT_THROW(continuous.observation(), std::logic_error);
  continuous.Reset(1);
  const std::array<float, 2> short_action = {0, 0};
  EXPECT_THROW(continuous.Step(short_action), std::invalid_argument);
  EXPECT_THROW(Drive(continuous, std::nanf(""), 0, 0), std::invalid_argument);
  EXPECT_THROW(continuous.Step(DiscreteAction(0)), std::invalid_argument);
  CarRacing discrete(CarRacingConfig{.continuous = false});
  discrete.Reset(1);
  EXPECT_THROW(discrete.Step(DiscreteAction(5)), std::invalid_argument);
  EXPECT_THROW(discrete.Step(DiscreteAction(-1)), std::invalid_argument);
  EXPECT_THROW(Drive(discrete, 0, 0, 0), std::invalid_argument);
  EXPECT_THROW(CarRacing(CarRacingConfig{.supersample = 0}), std::invalid_argument);
  EXPECT_THROW(CarRacing(CarRacingConfig{.lap_complete_percent = 1.5}), std::invalid_argument);
}

TEST(CarRacingTest, OutOfBoundsActionsAreClippedToTheBox) {
  CarRacing a;
  CarRacing b;
  a.Reset(12);
  b.Reset(12);
  for (int k = 0; k < 50; ++k) {
    const StepResult ra = Drive(a, 3.0f, 2.0f, -1.0f);
    const StepResult rb = Drive(b, 1.0f, 1.0f, 0.0f);
    ASSERT_EQ(ra.reward, rb.reward);
  }
  EXPECT_EQ(a.car().position.x, b.car().position.x);
}

// The centroid of the hull's red pixels in the lower middle of a 96 x 96 picture (red kerbs
// elsewhere blend to similar colours), or (-1, -1) when there are fewer than 8.
std::array<double, 2> RedCentroid(const std::vector<uint8_t>& rgb) {
  double sx = 0, sy = 0, count = 0;
  for (int y = 56; y < 84; ++y) {
    for (int x = 32; x < 64; ++x) {
      const uint8_t* p = &rgb[(y * 96 + x) * 3];
      if (p[0] > 170 && p[0] < 235 && p[1] < 40 && p[2] < 40) {  // Hull red, not kerb red.
        sx += x + 0.5;
        sy += y + 0.5;
        count += 1;
      }
    }
  }
  if (count < 8) return {-1, -1};
  return {sx / count, sy / count};
}

TEST(CarRacingTest, PictureShowsTheCarAtItsPlaceTurningWithIt) {
  CarRacing env;
  CarRacingPilot pilot;
  env.Reset(31);
  std::vector<uint8_t> rgb;
  int width = 0, height = 0;
  double start_angle = env.car().angle;
  bool turned = false;
  for (int k = 0; k < 600 && !turned; ++k) {
    env.Step(pilot.Act(env));
    if (k < 60) continue;  // After the zoom-in (t >= 1 s).
    env.Render(&rgb, &width, &height);
    ASSERT_EQ(width, 96);
    ASSERT_EQ(height, 96);
    // The car stays at the same place of the picture, pointing up, whichever way it faces.
    const auto c = RedCentroid(rgb);
    EXPECT_NEAR(c[0], 48, 2.5) << "step " << k;
    EXPECT_NEAR(c[1], 72, 3) << "step " << k;
    turned = std::abs(env.car().angle - start_angle) > 1.5;
  }
  EXPECT_TRUE(turned);
  // observation() is the same picture over 255.
  const auto obs = env.observation();
  ASSERT_EQ(obs.size(), rgb.size());
  for (std::size_t k = 0; k < rgb.size(); k += 97) EXPECT_FLOAT_EQ(obs[k], rgb[k] / 255.0f);
}

// Brightness of the speed indicator's column (slot 5: surface x 125-150, pixels 12-14).
int SpeedBar(const std::vector<uint8_t>& rgb) {
  int sum = 0;
  for (int y = 84; y < 96; ++y) {
    for (int x = 12; x < 15; ++x) sum += rgb[(y * 96 + x) * 3 + 1];
  }
  return sum;
}

TEST(CarRacingTest, IndicatorBarShowsTheSpeed) {
  CarRacing env;
  env.Reset(14);
  const int resting = SpeedBar(Rendered(env).rgb);
  for (int k = 0; k < 20; ++k) Drive(env, 0, 1, 0);
  const int slow = SpeedBar(Rendered(env).rgb);
  for (int k = 0; k < 30; ++k) Drive(env, 0, 1, 0);
  const int fast = SpeedBar(Rendered(env).rgb);
  EXPECT_LT(resting, 100);
  EXPECT_GT(slow, resting + 250);
  EXPECT_GT(fast, slow + 250);
}

TEST(CarRacingTest, DomainRandomisationDrawsNewColoursEachReset) {
  CarRacing env(CarRacingConfig{.domain_randomize = true});
  env.Reset(1);
  const Rgb first = env.scene().background;
  env.Reset();
  const Rgb second = env.scene().background;
  EXPECT_NE(first, second);
  EXPECT_EQ(CarRacingScene{}.background, (Rgb{102, 204, 102}));
  CarRacing again(CarRacingConfig{.domain_randomize = true});
  again.Reset(1);
  EXPECT_EQ(again.scene().background, first);
  // The grass is the background with 20 added to one channel.
  const Rgb grass = again.scene().grass;
  EXPECT_EQ(std::abs(grass.r - first.r) + std::abs(grass.g - first.g) + std::abs(grass.b - first.b),
            20);
}

TEST(CarRacingTest, VideoFramesAreDrawnAtTheirSize) {
  CarRacing env;
  env.Reset(3);
  std::vector<uint8_t> rgb;
  env.RenderSized(CarRacing::kVideoWidth, CarRacing::kVideoHeight, &rgb);
  EXPECT_EQ(rgb.size(), 600u * 400u * 3u);
  EXPECT_EQ(env.SupersampleFor(600, 400), 2);
  EXPECT_EQ(env.SupersampleFor(96, 96), 4);
  EXPECT_EQ(env.SupersampleFor(1000, 800), 1);
}

}  // namespace
}  // namespace rl::envs
