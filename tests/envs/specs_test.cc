#include "envs/specs.h"

#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "envs/registry.h"

namespace rl::envs {
namespace {

// Every field of the two specs, so that a mismatch names the field.
void ExpectSameSpec(const EnvSpec& built, const EnvSpec& looked_up, const std::string& id) {
#define EXPECT_SAME_FIELD(field) EXPECT_EQ(built.field, looked_up.field) << id
  EXPECT_SAME_FIELD(id);
  EXPECT_SAME_FIELD(observation_size);
  EXPECT_SAME_FIELD(num_actions);
  EXPECT_SAME_FIELD(max_episode_steps);
  EXPECT_SAME_FIELD(reward_threshold);
  EXPECT_SAME_FIELD(action_dim);
  EXPECT_SAME_FIELD(action_low);
  EXPECT_SAME_FIELD(action_high);
  EXPECT_SAME_FIELD(frame_height);
  EXPECT_SAME_FIELD(frame_width);
  EXPECT_SAME_FIELD(frame_stack);
  EXPECT_SAME_FIELD(render_width);
  EXPECT_SAME_FIELD(render_height);
#undef EXPECT_SAME_FIELD
}

// The values every spec must hold: the references' registrations (Gymnasium, bsuite, the KUKA
// tutorial's env), read without building an env.
TEST(SpecsTest, SpecsHoldTheReferencesValues) {
  struct Row {
    const char* id;
    int observation_size, num_actions, action_dim, max_episode_steps;
    double reward_threshold;
    std::vector<float> low, high;
    int render_width, render_height;
  };
  const std::vector<Row> rows = {
      {"CartPole-v1", 4, 2, 0, 500, 475.0, {}, {}, 600, 400},
      {"Catch-v0", 50, 3, 0, 9, 0.9, {}, {}, 40, 80},
      {"Pendulum-v1", 3, 0, 1, 200, -200.0, {-2.0f}, {2.0f}, 500, 500},
      {"LunarLander-v3", 8, 4, 0, 1000, 200.0, {}, {}, 600, 400},
      {"LunarLanderContinuous-v3", 8, 0, 2, 1000, 200.0, {-1.0f, -1.0f}, {1.0f, 1.0f}, 600, 400},
      {"CarRacing-v3", 27648, 0, 3, 1000, 900.0, {-1.0f, 0.0f, 0.0f}, {1.0f, 1.0f, 1.0f}, 96, 96},
      {"CarRacingDiscrete-v3", 27648, 5, 0, 1000, 900.0, {}, {}, 96, 96},
      {"KukaDiverseObjectGrasping-v0", 2, 7, 0, 15, 0.6, {}, {}, 48, 48},
      {"KukaDiverseObjectGraspingTest-v0", 2, 7, 0, 20, 0.6, {}, {}, 48, 48},
  };
  for (const Row& row : rows) {
    const EnvSpec spec = LookupSpec(row.id);
    EXPECT_EQ(spec.id, row.id);
    EXPECT_EQ(spec.observation_size, row.observation_size) << row.id;
    EXPECT_EQ(spec.num_actions, row.num_actions) << row.id;
    EXPECT_EQ(spec.action_dim, row.action_dim) << row.id;
    EXPECT_EQ(spec.continuous(), row.action_dim > 0) << row.id;
    EXPECT_EQ(spec.max_episode_steps, row.max_episode_steps) << row.id;
    EXPECT_EQ(spec.reward_threshold, row.reward_threshold) << row.id;
    EXPECT_EQ(spec.action_low, row.low) << row.id;
    EXPECT_EQ(spec.action_high, row.high) << row.id;
    EXPECT_EQ(spec.render_width, row.render_width) << row.id;
    EXPECT_EQ(spec.render_height, row.render_height) << row.id;
    EXPECT_EQ(spec.frame_stack, 0) << row.id;
  }
}

// The static spec of every registered id is the spec of the env MakeEnv builds, Render() refuses
// to draw before the first Reset, and the native render size is what it draws (KUKA is left out:
// building it needs an OpenGL context per id, and its spec is checked against the env in its own
// tests).
TEST(SpecsTest, EveryRegisteredIdHasTheSpecOfTheEnvItBuilds) {
  for (const std::string& id : RegisteredEnvs()) {
    if (id.rfind("Kuka", 0) == 0) continue;
    auto env = MakeEnv(id);
    ExpectSameSpec(env->spec(), LookupSpec(id), id);
    std::vector<uint8_t> rgb;
    int width = 0, height = 0;
    EXPECT_THROW(env->Render(&rgb, &width, &height), std::logic_error) << id << " before Reset";
    env->Reset(1);
    env->Render(&rgb, &width, &height);
    EXPECT_EQ(width, env->spec().render_width) << id;
    EXPECT_EQ(height, env->spec().render_height) << id;
  }
}

// The spec lookup and the registry expand the one list of envs (env_list.inc) separately: every
// registered id has a spec under its own id, and every id with a spec is registered.
TEST(SpecsTest, EveryRegisteredIdHasASpecAndEverySpecIdIsRegistered) {
  const std::vector<std::string> registered = RegisteredEnvs();
  EXPECT_FALSE(registered.empty());
  EXPECT_EQ(SpecIds(), registered);
  for (const std::string& id : registered) EXPECT_EQ(LookupSpec(id).id, id);
}

TEST(SpecsTest, PixelIdsHaveTheSpecOfTheImagePipeline) {
  for (const std::string id :
       {"Catch-v0+pixels(width=5,height=10,stack=2,max-pool=0)",
        "CartPole-v1+pixels(width=84,height=84,stack=4,skip=4)",
        "CartPole-v1+pixels(width=0,height=0,stack=3,crop-top=100,crop-left=10,crop-right=30)",
        "LunarLanderContinuous-v3+pixels(width=42,height=42,stack=2,skip=3)",
        "CarRacing-v3+pixels(skip=5,time-limit=18000,lap-ends=0)"}) {
    ExpectSameSpec(MakeEnv(id)->spec(), LookupSpec(id), id);
  }
}

TEST(SpecsTest, ContinuousSpecsHavePerDimensionBounds) {
  const EnvSpec car = CarRacingSpec(true);
  EXPECT_TRUE(car.continuous());
  EXPECT_EQ(car.action_width(), 3);
  EXPECT_EQ(car.action_low, (std::vector<float>{-1, 0, 0}));
  EXPECT_EQ(car.action_high, (std::vector<float>{1, 1, 1}));
  const EnvSpec pendulum = LookupSpec("Pendulum-v1");
  EXPECT_EQ(pendulum.action_width(), 1);
  EXPECT_EQ(pendulum.action_low, std::vector<float>{-2});
  EXPECT_FALSE(LookupSpec("CartPole-v1").continuous());
  EXPECT_EQ(LookupSpec("CartPole-v1").action_width(), 1);
}

TEST(SpecsTest, UnknownIdsAndBadPixelSettingsAreRefused) {
  EXPECT_THROW(LookupSpec("NoSuchEnv-v0"), std::invalid_argument);
  EXPECT_THROW(LookupSpec("CartPole-v1+pixels(width=84,height=0)"), std::invalid_argument);
  EXPECT_THROW(LookupSpec("CartPole-v1+pixels(crop-left=300,crop-right=300)"),
               std::invalid_argument);
}

TEST(CheckActionTest, DiscreteActionsAreIntegerIndicesInRange) {
  const EnvSpec spec = CartPoleSpec();
  const float ok[] = {1.0f};
  EXPECT_EQ(CheckAction(spec, ok), nullptr);
  const float fraction[] = {0.5f};
  EXPECT_STREQ(CheckAction(spec, fraction), "discrete action not an integer");
  const float high[] = {2.0f};
  EXPECT_STREQ(CheckAction(spec, high), "discrete action out of range");
  const float negative[] = {-1.0f};
  EXPECT_STREQ(CheckAction(spec, negative), "discrete action out of range");
  const float two[] = {0.0f, 1.0f};
  EXPECT_STREQ(CheckAction(spec, two), "action of the wrong width");
  const float nan[] = {std::numeric_limits<float>::quiet_NaN()};
  EXPECT_STREQ(CheckAction(spec, nan), "action not finite");
}

TEST(CheckActionTest, ContinuousActionsStayInTheirBoundsUpToTheTolerance) {
  const EnvSpec spec = CarRacingSpec(true);
  const float ok[] = {-1.0f, 0.0f, 1.0f};
  EXPECT_EQ(CheckAction(spec, ok), nullptr);
  const float below[] = {0.0f, -0.01f, 0.5f};  // gas below 0
  EXPECT_STREQ(CheckAction(spec, below), "continuous action outside the bounds");
  EXPECT_EQ(CheckAction(spec, below, 0.02f), nullptr);
  const float inf[] = {0.0f, std::numeric_limits<float>::infinity(), 0.5f};
  EXPECT_STREQ(CheckAction(spec, inf, 1e9f), "action not finite");
}

// The same observations and actions: rules and limits may differ, shapes and bounds may not.
TEST(SameShapeTest, ComparesObservationsAndActionsNotRules) {
  const std::string pixels = "CarRacing-v3+pixels(skip=5,crop-bottom=12,width=84,height=84,stack=4";
  const EnvSpec training = LookupSpec(pixels + ",noop-start=45,off-track=1)");
  const EnvSpec standard = LookupSpec(pixels + ")");
  EXPECT_TRUE(SameShape(training, standard));
  EXPECT_FALSE(SameShape(standard, LookupSpec(pixels.substr(0, pixels.size() - 1) + "3)")));
  EXPECT_FALSE(SameShape(CarRacingSpec(true), CarRacingSpec(false)));
  EnvSpec narrower = standard;
  narrower.action_high[1] = 0.5f;  // gas
  EXPECT_FALSE(SameShape(standard, narrower));
  EXPECT_TRUE(SameShape(CartPoleSpec(), CartPoleSpec()));
}

TEST(EnvActTest, DispatchesByActionKindAndRefusesBadActions) {
  auto cartpole = MakeEnv("CartPole-v1");
  cartpole->Reset(3);
  const float right[] = {1.0f};
  EXPECT_NO_THROW(cartpole->Step(right));
  const float fraction[] = {0.5f};
  EXPECT_THROW(cartpole->Step(fraction), std::invalid_argument);
  auto lander = MakeEnv("LunarLanderContinuous-v3");
  lander->Reset(3);
  // Out of bounds is the env's to clip, not an error.
  const float strong[] = {5.0f, -5.0f};
  EXPECT_NO_THROW(lander->Step(strong));
  const float one[] = {0.0f};
  EXPECT_THROW(lander->Step(one), std::invalid_argument);
}

}  // namespace
}  // namespace rl::envs
