#include "envs/image/frame_stack.h"

#include <cstdint>
#include <memory>
#include <span>
#include <stdexcept>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "tests/envs/image/scripted_image_env.h"
#include "tests/envs/image/span_vectors.h"

namespace rl::envs {
namespace {

using testing::GrayShape;
using testing::RgbShape;
using testing::ScriptedImageEnv;
using testing::ScriptedStep;

// 2x1 grayscale frames of multiples of 51, so that each byte / 255 is a short decimal:
// 0 -> 0, 51 -> 0.2, 102 -> 0.4, 153 -> 0.6, 204 -> 0.8, 255 -> 1.
std::unique_ptr<ScriptedImageEnv> MakeScripted() {
  return std::make_unique<ScriptedImageEnv>(
      GrayShape(2, 1),
      std::vector<std::vector<uint8_t>>{{0, 51}, {102, 153}, {204, 255}, {51, 0}, {255, 255}},
      std::vector<ScriptedStep>{
          {.reward = 1}, {.reward = 2}, {.reward = 3, .terminated = true}, {.reward = 4}});
}

ImagePipelineConfig Stack(int stack) {
  ImagePipelineConfig config;
  config.stack = stack;
  return config;
}

TEST(FrameStackTest, SpecDescribesThePixelObservation) {
  FrameStack env(MakeScripted(), Stack(3));
  EXPECT_EQ(env.spec().frame_height, 1);
  EXPECT_EQ(env.spec().frame_width, 2);
  EXPECT_EQ(env.spec().frame_stack, 3);
  EXPECT_EQ(env.spec().observation_size, 3 * 1 * 2);
  EXPECT_EQ(env.spec().id, "Scripted-v0");
  EXPECT_EQ(env.spec().num_actions, 3);
  EXPECT_EQ(env.spec().max_episode_steps, 10);
  EXPECT_EQ(env.spec().reward_threshold, 2.5);
  // Before any Reset the observation has its size and is all 0.
  EXPECT_EQ(Floats(env.observation()), std::vector<float>(6, 0.0f));
}

TEST(FrameStackTest, ResetRepeatsTheFirstFrameAndStepsShiftTheStack) {
  FrameStack env(MakeScripted(), Stack(3));
  env.Reset(0);
  EXPECT_EQ(Floats(env.observation()), (std::vector<float>{0, 0.2f, 0, 0.2f, 0, 0.2f}));
  EXPECT_EQ(env.Step(DiscreteAction(0)).reward, 1.0);
  EXPECT_EQ(Floats(env.observation()), (std::vector<float>{0, 0.2f, 0, 0.2f, 0.4f, 0.6f}));
  EXPECT_EQ(Bytes(env.frame()), (std::vector<uint8_t>{102, 153}));
  env.Step(DiscreteAction(0));
  EXPECT_EQ(Floats(env.observation()), (std::vector<float>{0, 0.2f, 0.4f, 0.6f, 0.8f, 1.0f}));
  EXPECT_TRUE(env.Step(DiscreteAction(0)).terminated);
  // The oldest frame (the reset frame) drops out.
  EXPECT_EQ(Floats(env.observation()), (std::vector<float>{0.4f, 0.6f, 0.8f, 1.0f, 0.2f, 0}));
  EXPECT_EQ(Bytes(env.frame()), (std::vector<uint8_t>{51, 0}));
}

TEST(FrameStackTest, NoFrameCrossesAnEpisodeBoundary) {
  FrameStack env(MakeScripted(), Stack(3));
  env.Reset(0);
  env.Step(DiscreteAction(0));
  env.Step(DiscreteAction(0));
  env.Reset();
  EXPECT_EQ(Floats(env.observation()), (std::vector<float>{0, 0.2f, 0, 0.2f, 0, 0.2f}));
  EXPECT_EQ(Bytes(env.frame()), (std::vector<uint8_t>{0, 51}));
  env.Step(DiscreteAction(0));
  EXPECT_EQ(Floats(env.observation()), (std::vector<float>{0, 0.2f, 0, 0.2f, 0.4f, 0.6f}));
}

TEST(FrameStackTest, ObservationIsEachByteDividedBy255) {
  // Bytes 1 and 254: float division gives 1.0f / 255.0f and 254.0f / 255.0f exactly.
  FrameStack env(std::make_unique<ScriptedImageEnv>(GrayShape(2, 1),
                                                    std::vector<std::vector<uint8_t>>{{1, 254}}),
                 Stack(1));
  env.Reset(0);
  EXPECT_EQ(Floats(env.observation()), (std::vector<float>{1.0f / 255.0f, 254.0f / 255.0f}));
  EXPECT_EQ(Bytes(env.frame()), (std::vector<uint8_t>{1, 254}));
}

TEST(FrameStackTest, RejectsRgbInputBadStacksAndUseBeforeReset) {
  EXPECT_THROW(FrameStack(std::make_unique<ScriptedImageEnv>(
                              RgbShape(1, 1), std::vector<std::vector<uint8_t>>{{0, 0, 0}}),
                          Stack(2)),
               std::invalid_argument);
  EXPECT_THROW(FrameStack(MakeScripted(), Stack(0)), std::invalid_argument);
  EXPECT_THROW(FrameStack(nullptr, Stack(2)), std::invalid_argument);
  FrameStack env(MakeScripted(), Stack(2));
  EXPECT_THROW(env.Step(DiscreteAction(0)), std::logic_error);
  EXPECT_THROW(env.frame(), std::logic_error);
}

}  // namespace
}  // namespace rl::envs
