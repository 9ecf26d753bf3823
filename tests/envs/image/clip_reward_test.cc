#include "envs/image/clip_reward.h"

#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <stdexcept>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "envs/image/frame_stack.h"
#include "tests/envs/image/scripted_image_env.h"

namespace rl::envs {
namespace {

using testing::GrayShape;
using testing::ScriptedImageEnv;
using testing::ScriptedStep;

TEST(ClipRewardTest, ClampsRewardsToPlusMinusOneAndPassesTheFlags) {
  const std::vector<ScriptedStep> script = {{.reward = 5},
                                            {.reward = -3},
                                            {.reward = 0.5},
                                            {.reward = -0.25},
                                            {.reward = 1},
                                            {.reward = -1},
                                            {.reward = 0},
                                            {.reward = 1.0000001, .truncated = true},
                                            {.reward = -7, .terminated = true}};
  ClipReward env(std::make_unique<ScriptedImageEnv>(
      GrayShape(1, 1), std::vector<std::vector<uint8_t>>(script.size() + 1, {0}), script));
  env.Reset(0);
  const std::vector<double> expected = {1, -1, 0.5, -0.25, 1, -1, 0, 1, -1};
  for (std::size_t t = 0; t < script.size(); ++t) {
    const StepResult r = env.Step(DiscreteAction(0));
    EXPECT_EQ(r.reward, expected[t]) << "step " << t + 1;
    EXPECT_EQ(r.terminated, script[t].terminated) << "step " << t + 1;
    EXPECT_EQ(r.truncated, script[t].truncated) << "step " << t + 1;
  }
}

TEST(ClipRewardTest, NanPassesThrough) {
  ClipReward env(std::make_unique<ScriptedImageEnv>(
      GrayShape(1, 1), std::vector<std::vector<uint8_t>>(2, {0}),
      std::vector<ScriptedStep>{{.reward = std::numeric_limits<double>::quiet_NaN()}}));
  env.Reset(0);
  EXPECT_TRUE(std::isnan(env.Step(DiscreteAction(0)).reward));
}

TEST(ClipRewardTest, ForwardsSpecObservationAndFrame) {
  ImagePipelineConfig config;
  config.stack = 2;
  auto stack = std::make_unique<FrameStack>(
      std::make_unique<ScriptedImageEnv>(GrayShape(1, 1),
                                         std::vector<std::vector<uint8_t>>{{51}, {102}},
                                         std::vector<ScriptedStep>{{.reward = 3}}),
      config);
  ClipReward env(std::move(stack));
  EXPECT_EQ(env.spec().frame_stack, 2);
  EXPECT_EQ(env.spec().observation_size, 2);
  env.Reset(0);
  EXPECT_EQ(env.Step(DiscreteAction(0)).reward, 1.0);
  EXPECT_EQ(env.frame()[0], 102);
  EXPECT_EQ(env.observation()[0], 0.2f);
  EXPECT_EQ(env.observation()[1], 0.4f);
  EXPECT_THROW(ClipReward(nullptr), std::invalid_argument);
}

}  // namespace
}  // namespace rl::envs
