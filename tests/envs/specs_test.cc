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
  EXPECT_EQ(built.id, looked_up.id) << id;
  EXPECT_EQ(built.observation_size, looked_up.observation_size) << id;
  EXPECT_EQ(built.num_actions, looked_up.num_actions) << id;
  EXPECT_EQ(built.max_episode_steps, looked_up.max_episode_steps) << id;
  EXPECT_EQ(built.reward_threshold, looked_up.reward_threshold) << id;
  EXPECT_EQ(built.action_dim, looked_up.action_dim) << id;
  EXPECT_EQ(built.action_low, looked_up.action_low) << id;
  EXPECT_EQ(built.action_high, looked_up.action_high) << id;
  EXPECT_EQ(built.frame_height, looked_up.frame_height) << id;
  EXPECT_EQ(built.frame_width, looked_up.frame_width) << id;
  EXPECT_EQ(built.frame_stack, looked_up.frame_stack) << id;
  EXPECT_EQ(built.render_width, looked_up.render_width) << id;
  EXPECT_EQ(built.render_height, looked_up.render_height) << id;
}

// The static spec of every registered id is the spec of the env MakeEnv builds, and the native
// render size is what Render() draws (KUKA is left out: building it needs an OpenGL context per
// id, and its spec is checked against the env in its own tests).
TEST(SpecsTest, EveryRegisteredIdHasTheSpecOfTheEnvItBuilds) {
  for (const std::string& id : RegisteredEnvs()) {
    if (id.rfind("Kuka", 0) == 0) continue;
    auto env = MakeEnv(id);
    ExpectSameSpec(env->spec(), LookupSpec(id), id);
    env->Reset(1);
    std::vector<uint8_t> rgb;
    int width = 0, height = 0;
    env->Render(&rgb, &width, &height);
    EXPECT_EQ(width, env->spec().render_width) << id;
    EXPECT_EQ(height, env->spec().render_height) << id;
  }
}

TEST(SpecsTest, PixelIdsHaveTheSpecOfTheImagePipeline) {
  for (const std::string id :
       {"Catch-v0+pixels(width=5,height=10,stack=2,max-pool=0)",
        "CartPole-v1+pixels(width=84,height=84,stack=4,skip=4)",
        "CartPole-v1+pixels(width=0,height=0,stack=3,crop-top=100,crop-left=10,crop-right=30)",
        "LunarLanderContinuous-v3+pixels(width=42,height=42,stack=2,skip=3)"}) {
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

TEST(EnvActTest, DispatchesByActionKindAndRefusesBadActions) {
  auto cartpole = MakeEnv("CartPole-v1");
  cartpole->Reset(3);
  const float right[] = {1.0f};
  EXPECT_NO_THROW(cartpole->Act(right));
  const float fraction[] = {0.5f};
  EXPECT_THROW(cartpole->Act(fraction), std::invalid_argument);
  auto lander = MakeEnv("LunarLanderContinuous-v3");
  lander->Reset(3);
  // Out of bounds is the env's to clip, not an error.
  const float strong[] = {5.0f, -5.0f};
  EXPECT_NO_THROW(lander->Act(strong));
  const float one[] = {0.0f};
  EXPECT_THROW(lander->Act(one), std::invalid_argument);
}

}  // namespace
}  // namespace rl::envs
