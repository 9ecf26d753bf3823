#include "envs/pixel_spec.h"

#include <stdexcept>
#include <string>
#include <tuple>

#include <gtest/gtest.h>

#include "envs/registry.h"
#include "envs/specs.h"
#include "tests/common/error_of.h"

namespace rl::envs {
namespace {

TEST(PixelSpecTest, AnIdWithoutPixelsIsJustTheRegisteredId) {
  const EnvIdParts p = ParseEnvId("CartPole-v1");
  EXPECT_EQ(p.base, "CartPole-v1");
  EXPECT_FALSE(p.pixels);
}

TEST(PixelSpecTest, ReadsEveryKey) {
  const EnvIdParts p = ParseEnvId(
      "Catch-v0+pixels(width=6,height=12,stack=3,skip=2,max-pool=0,crop-top=1,crop-bottom=2,"
      "crop-left=3,crop-right=4,render-width=40,render-height=80,noop-start=45,time-limit=7)");
  EXPECT_EQ(p.base, "Catch-v0");
  ASSERT_TRUE(p.pixels);
  EXPECT_EQ(p.image.width, 6);
  EXPECT_EQ(p.image.height, 12);
  EXPECT_EQ(p.image.stack, 3);
  EXPECT_EQ(p.image.frame_skip, 2);
  EXPECT_FALSE(p.image.max_pool);
  EXPECT_EQ(p.image.crop_top, 1);
  EXPECT_EQ(p.image.crop_bottom, 2);
  EXPECT_EQ(p.image.crop_left, 3);
  EXPECT_EQ(p.image.crop_right, 4);
  EXPECT_EQ(p.image.render_width, 40);
  EXPECT_EQ(p.image.render_height, 80);
  EXPECT_EQ(p.image.noop_start, 45);
  EXPECT_EQ(p.image.time_limit, 7);
  EXPECT_FALSE(p.off_track);
  EXPECT_TRUE(p.lap_ends);
  EXPECT_FALSE(p.image.clip_rewards);
  // CarRacing's own rules.
  const EnvIdParts car = ParseEnvId("CarRacing-v3+pixels(off-track=1,lap-ends=0)");
  EXPECT_TRUE(car.off_track);
  EXPECT_FALSE(car.lap_ends);
  EXPECT_FALSE(car.pedals);
  EXPECT_TRUE(ParseEnvId("CarRacing-v3+pixels(pedals=1)").pedals);
}

TEST(PixelSpecTest, KeepsTheDefaultsOfKeysNotGiven) {
  const EnvIdParts p = ParseEnvId("CartPole-v1+pixels()");
  const ImagePipelineConfig defaults;
  EXPECT_TRUE(p.pixels);
  EXPECT_EQ(p.image.width, defaults.width);
  EXPECT_EQ(p.image.stack, defaults.stack);
  EXPECT_EQ(p.image.max_pool, defaults.max_pool);
}

TEST(PixelSpecTest, RefusesBadSpecsWithTheReason) {
  // The message of the error ParseEnvId throws, which must be a std::invalid_argument.
  const auto message = [](const std::string& id) {
    EXPECT_THROW(ParseEnvId(id), std::invalid_argument) << id;
    return ErrorOf([&] { ParseEnvId(id); });
  };
  EXPECT_NE(message("Catch-v0+pixels(colour=1)").find("unknown pixels key 'colour'"),
            std::string::npos);
  EXPECT_NE(message("Catch-v0+pixels(width=five)").find("width must be an integer"),
            std::string::npos);
  EXPECT_NE(message("Catch-v0+pixels(width=5").find("ending in ')'"), std::string::npos);
  EXPECT_NE(message("Catch-v0+pixels(width=5)x").find("ending in ')'"), std::string::npos);
  EXPECT_NE(message("Catch-v0+pixels(stack)").find("expected key=value"), std::string::npos);
  EXPECT_NE(message("Catch-v0+pixels(max-pool=2)").find("max-pool is 0 or 1"), std::string::npos);
  EXPECT_NE(message("Catch-v0+pixels(stack=0)").find("stack"), std::string::npos);
  EXPECT_NE(message("Catch-v0+pixels(off-track=3)").find("off-track is 0 or 1"), std::string::npos);
  EXPECT_NE(message("Catch-v0+pixels(noop-start=-1)").find("noop_start"), std::string::npos);
  EXPECT_NE(message("Catch-v0+pixels(time-limit=-1)").find("time_limit"), std::string::npos);
  EXPECT_NE(message("Catch-v0+pixels(lap-ends=0)").find("lap-ends applies to CarRacing only"),
            std::string::npos);
  EXPECT_NE(message("Catch-v0+pixels(off-track=1)").find("off-track applies to CarRacing only"),
            std::string::npos);
  EXPECT_NE(message("CarRacing-v3+pixels(lap-ends=2)").find("lap-ends is 0 or 1"),
            std::string::npos);
  EXPECT_NE(message("CarRacing-v3+pixels(off-track-grace=20)").find("with off-track=1"),
            std::string::npos);
  EXPECT_NE(message("CarRacing-v3+pixels(off-track=1,off-track-grace=-1)").find("frames >= 0"),
            std::string::npos);
  EXPECT_NE(message("CarRacing-v3+pixels(pedals=2)").find("pedals is 0 or 1"), std::string::npos);
  EXPECT_NE(message("CarRacingDiscrete-v3+pixels(pedals=1)").find("pedals applies to CarRacing-v3"),
            std::string::npos);
  EXPECT_NE(message("Catch-v0+pixels(pedals=1)").find("pedals applies to CarRacing-v3"),
            std::string::npos);
}

// time-limit replaces the env's own limit, in inner steps: Catch's 9 steps cut at 3 (with an
// action repeat of 2, the outer step that holds the third inner one, the second, is truncated).
TEST(PixelSpecTest, TimeLimitReplacesTheEnvsOwn) {
  const std::string id = "Catch-v0+pixels(width=5,height=10,stack=1,skip=2,time-limit=3)";
  auto env = MakeEnv(id);
  EXPECT_EQ(LookupSpec(id).max_episode_steps, 2);
  EXPECT_EQ(env->spec().max_episode_steps, 2);
  env->Reset(1);
  const StepResult first = env->Step(DiscreteAction(1));
  EXPECT_FALSE(first.terminated || first.truncated);
  const StepResult second = env->Step(DiscreteAction(1));
  EXPECT_TRUE(second.truncated);
  EXPECT_FALSE(second.terminated);
  EXPECT_EQ(LookupSpec("CarRacing-v3+pixels(skip=5,time-limit=18000)").max_episode_steps, 3600);
}

// Frames larger than the messages carry are refused, before their sizes overflow an int (the
// observation size of 2 x 333333310 x 5 did). Found by fuzz/fuzz_env_id.
TEST(PixelSpecTest, RefusesFramesLargerThanTheMessagesCarry) {
  for (const char* id : {"Catch-v0+pixels(width=5,height=333333310,stack=2,max-pool=0)",
                         "Catch-v0+pixels(width=4097,height=5)", "Catch-v0+pixels(stack=65)",
                         "Catch-v0+pixels(render-width=5000,render-height=10,width=0,height=0)"}) {
    EXPECT_THROW(LookupSpec(id), std::invalid_argument) << id;
  }
  EXPECT_EQ(LookupSpec("Catch-v0+pixels(width=4096,height=4096,stack=64)").observation_size,
            64 * 4096 * 4096);
}

TEST(PixelSpecTest, MakeEnvBuildsThePipelineTheIdDescribes) {
  auto env = MakeEnv("Catch-v0+pixels(width=5,height=10,stack=2,max-pool=0)");
  const EnvSpec& spec = env->spec();
  EXPECT_EQ(spec.id, "Catch-v0");
  // Frames of 5 x 10 pixels (width, height), two stacked.
  EXPECT_EQ(std::tie(spec.frame_width, spec.frame_height, spec.frame_stack), std::tuple(5, 10, 2));
  EXPECT_EQ(spec.observation_size, 100);
  EXPECT_EQ(spec.num_actions, 3);
  env->Reset(3);
  // One pixel per cell: two bright pixels (the ball in row 0, the paddle in row 9, column 2).
  int bright = 0;
  for (uint8_t v : env->frame()) bright += v > 128;
  EXPECT_EQ(bright, 2);
  EXPECT_GT(env->frame()[9 * 5 + 2], 128);
  EXPECT_THROW(MakeEnv("Nope-v0+pixels(stack=2)"), std::invalid_argument);
}

}  // namespace
}  // namespace rl::envs
