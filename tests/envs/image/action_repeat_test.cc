#include "envs/image/action_repeat.h"

#include <cstdint>
#include <memory>
#include <span>
#include <stdexcept>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "tests/envs/image/scripted_image_env.h"

namespace rl::envs {
namespace {

using testing::RgbShape;
using testing::ScriptedImageEnv;
using testing::ScriptedStep;

std::vector<uint8_t> Bytes(std::span<const uint8_t> image) { return {image.begin(), image.end()}; }

// Hand-made 3x2 RGB frames, pixels as (R, G, B), row by row. kF0 is shown after Reset, kF1.. after
// the inner steps.
const std::vector<uint8_t> kF0(18, 250);
const std::vector<uint8_t> kF1 = {10, 200, 30, 0,   0,  0,  255, 1, 2,  //
                                  5,  5,   5,  100, 50, 25, 9,   9, 9};
const std::vector<uint8_t> kF2 = {20, 100, 30, 7,  0,   0,  0, 3, 2,  //
                                  6,  4,   5,  50, 100, 25, 9, 8, 10};
const std::vector<uint8_t> kF3(18, 1);
const std::vector<uint8_t> kF4 = {3, 3, 3, 0, 0, 0, 2, 2, 2,  //
                                  0, 0, 0, 4, 4, 4, 0, 0, 0};

// A scripted env showing kF0..kF4 with rewards 1, 2, 4, 8 (so every sum of consecutive rewards
// tells which inner steps it covers) and the given episode ends.
std::unique_ptr<ScriptedImageEnv> MakeScripted(std::vector<ScriptedStep> steps = {
                                                   {1}, {2}, {4}, {8}}) {
  return std::make_unique<ScriptedImageEnv>(
      RgbShape(3, 2), std::vector<std::vector<uint8_t>>{kF0, kF1, kF2, kF3, kF4}, std::move(steps));
}

ImagePipelineConfig Skip(int frame_skip, bool max_pool = true) {
  ImagePipelineConfig config;
  config.frame_skip = frame_skip;
  config.max_pool = max_pool;
  return config;
}

TEST(ActionRepeatTest, SumsTheRewardsOverTheSkip) {
  auto inner = MakeScripted();
  ScriptedImageEnv* scripted = inner.get();
  ActionRepeat env(std::move(inner), Skip(2));
  env.Reset(7);
  // Inner steps 1 + 2, then 3 + 4.
  EXPECT_EQ(env.Step(DiscreteAction(1)).reward, 1.0 + 2.0);
  EXPECT_EQ(scripted->steps_taken, 2);
  const StepResult second = env.Step(DiscreteAction(1));
  EXPECT_EQ(second.reward, 4.0 + 8.0);
  EXPECT_FALSE(second.terminated);
  EXPECT_FALSE(second.truncated);
  EXPECT_EQ(scripted->steps_taken, 4);
  // observation() is the inner env's after its last step (the scripted env counts its steps).
  EXPECT_EQ(env.observation()[0], 4.0f);
}

TEST(ActionRepeatTest, StopsEarlyOnTermination) {
  auto inner = MakeScripted({{1}, {2, /*terminated=*/true}, {4}, {8}});
  ScriptedImageEnv* scripted = inner.get();
  ActionRepeat env(std::move(inner), Skip(4));
  env.Reset(0);
  const StepResult r = env.Step(DiscreteAction(0));
  EXPECT_EQ(r.reward, 1.0 + 2.0);
  EXPECT_TRUE(r.terminated);
  EXPECT_FALSE(r.truncated);
  EXPECT_EQ(scripted->steps_taken, 2);
}

TEST(ActionRepeatTest, StopsEarlyOnTruncation) {
  auto inner = MakeScripted({{1}, {2}, {4, false, /*truncated=*/true}, {8}});
  ScriptedImageEnv* scripted = inner.get();
  ActionRepeat env(std::move(inner), Skip(4));
  env.Reset(0);
  const StepResult r = env.Step(DiscreteAction(0));
  EXPECT_EQ(r.reward, 1.0 + 2.0 + 4.0);
  EXPECT_FALSE(r.terminated);
  EXPECT_TRUE(r.truncated);
  EXPECT_EQ(scripted->steps_taken, 3);
}

TEST(ActionRepeatTest, ImageIsTheMaxOfTheLastTwoRawFrames) {
  ActionRepeat env(MakeScripted(), Skip(2));
  env.Reset(0);
  EXPECT_EQ(Bytes(env.image()), kF0);
  env.Step(DiscreteAction(0));
  // Pixelwise max of kF1 and kF2.
  const std::vector<uint8_t> max12 = {20, 200, 30, 7,   0,   0,  255, 3, 2,  //
                                      6,  5,   5,  100, 100, 25, 9,   9, 10};
  EXPECT_EQ(Bytes(env.image()), max12);
  env.Step(DiscreteAction(0));
  // Pixelwise max of kF3 (all 1) and kF4.
  const std::vector<uint8_t> max34 = {3, 3, 3, 1, 1, 1, 2, 2, 2,  //
                                      1, 1, 1, 4, 4, 4, 1, 1, 1};
  EXPECT_EQ(Bytes(env.image()), max34);
}

TEST(ActionRepeatTest, FramesBeforeTheLastTwoDoNotCount) {
  ActionRepeat env(MakeScripted(), Skip(3));
  env.Reset(0);
  env.Step(DiscreteAction(0));
  // Max of kF2 and kF3 only: kF1's 200 and 255 must not show.
  const std::vector<uint8_t> max23 = {20, 100, 30, 7,  1,   1,  1, 3, 2,  //
                                      6,  4,   5,  50, 100, 25, 9, 8, 10};
  EXPECT_EQ(Bytes(env.image()), max23);
}

TEST(ActionRepeatTest, OneInnerStepGivesThatFrameAlone) {
  // The episode ends on the first inner step of a skip of 3: kF1 alone, not pooled with the
  // reset frame kF0 (all 250, which would show everywhere).
  ActionRepeat env(MakeScripted({{1, true}, {2}, {4}}), Skip(3));
  env.Reset(0);
  EXPECT_TRUE(env.Step(DiscreteAction(0)).terminated);
  EXPECT_EQ(Bytes(env.image()), kF1);
  // With frame_skip 1 every step is a single inner step.
  ActionRepeat single(MakeScripted(), Skip(1));
  single.Reset(0);
  single.Step(DiscreteAction(0));
  EXPECT_EQ(Bytes(single.image()), kF1);
  single.Step(DiscreteAction(0));
  EXPECT_EQ(Bytes(single.image()), kF2);
}

TEST(ActionRepeatTest, WithoutMaxPoolTheImageIsTheLastFrameAndOnlyItIsRendered) {
  auto inner = MakeScripted();
  ScriptedImageEnv* scripted = inner.get();
  ActionRepeat env(std::move(inner), Skip(2, /*max_pool=*/false));
  const int renders_before = scripted->renders;
  env.Reset(0);
  env.Step(DiscreteAction(0));
  EXPECT_EQ(Bytes(env.image()), kF2);
  EXPECT_EQ(scripted->renders - renders_before, 2);  // The reset frame and kF2.
}

TEST(ActionRepeatTest, ResetShowsTheResetFrameAgain) {
  ActionRepeat env(MakeScripted(), Skip(2));
  env.Reset(0);
  env.Step(DiscreteAction(0));
  env.Reset();
  EXPECT_EQ(Bytes(env.image()), kF0);
  EXPECT_EQ(env.observation()[0], 0.0f);
}

TEST(ActionRepeatTest, SpecDividesTheTimeLimitRoundingUp) {
  for (const auto& [skip, expected] : std::vector<std::pair<int, int>>{
           {1, 10}, {2, 5}, {3, 4}, {4, 3}, {9, 2}, {10, 1}, {25, 1}}) {
    ActionRepeat env(MakeScripted(), Skip(skip));
    EXPECT_EQ(env.spec().max_episode_steps, expected) << "frame_skip " << skip;
    EXPECT_EQ(env.spec().id, "Scripted-v0");
    EXPECT_EQ(env.spec().num_actions, 3);
    EXPECT_EQ(env.spec().observation_size, 1);
    EXPECT_EQ(env.spec().reward_threshold, 2.5);
    EXPECT_EQ(env.spec().frame_stack, 0);
  }
}

TEST(ActionRepeatTest, NativeSizeIsLearntFromOneResetWithSeedZero) {
  auto inner = MakeScripted();
  ScriptedImageEnv* scripted = inner.get();
  ActionRepeat env(std::move(inner), Skip(1));
  EXPECT_EQ(env.image_shape(), RgbShape(3, 2));
  EXPECT_EQ(scripted->resets, 1);
  EXPECT_EQ(scripted->last_seed, 0u);
}

TEST(ActionRepeatTest, ExplicitRenderSizeUsesRenderSizedAndNoProbe) {
  auto inner = MakeScripted();
  ScriptedImageEnv* scripted = inner.get();
  ImagePipelineConfig config = Skip(1);
  config.render_width = 6;
  config.render_height = 4;
  ActionRepeat env(std::move(inner), config);
  EXPECT_EQ(scripted->resets, 0);
  EXPECT_EQ(env.image_shape(), RgbShape(6, 4));
  env.Reset(0);
  EXPECT_EQ(scripted->last_sized_width, 6);
  EXPECT_EQ(scripted->last_sized_height, 4);
  ASSERT_EQ(env.image().size(), 6u * 4u * 3u);
  // kF0 is uniformly 250, so is its 2x enlargement.
  EXPECT_EQ(Bytes(env.image()), std::vector<uint8_t>(6 * 4 * 3, 250));
}

TEST(ActionRepeatTest, RenderForwardsToTheWrappedEnv) {
  ActionRepeat env(MakeScripted(), Skip(2));
  env.Reset(0);
  env.Step(DiscreteAction(0));
  // The wrapped env's own picture after its last inner step (kF2), not the pooled image.
  std::vector<uint8_t> rgb;
  int width = 0;
  int height = 0;
  env.Render(&rgb, &width, &height);
  EXPECT_EQ(rgb, kF2);
  EXPECT_EQ(width, 3);
  EXPECT_EQ(height, 2);
}

// noop_start plays zero actions after every Reset, their rewards discarded, and resets again when
// the episode ends during them.
TEST(ActionRepeatTest, NoOpStartPlaysZeroActionsAfterReset) {
  auto inner = MakeScripted({{1}, {2}, {4}, {8}});
  ScriptedImageEnv* scripted = inner.get();
  ImagePipelineConfig config = Skip(1, /*max_pool=*/false);
  config.noop_start = 2;
  ActionRepeat env(std::move(inner), config);
  const int renders_before = scripted->renders;
  env.Reset(3);
  EXPECT_EQ(scripted->steps_taken, 2);
  EXPECT_EQ(scripted->renders - renders_before, 1);  // only the frame after the no-ops
  EXPECT_EQ(Bytes(env.image()), kF2);
  EXPECT_EQ(env.Step(DiscreteAction(0)).reward,
            4.0);  // the third inner step; 1 and 2 were discarded

  // An episode that ends during the no-ops starts again; one that always does is refused after
  // ten restarts instead of looping for ever (the scripted env ends every episode at step 2).
  auto ending = MakeScripted({{1}, {.reward = 2, .terminated = true}, {4}, {8}});
  ScriptedImageEnv* ending_env = ending.get();
  config.noop_start = 3;
  ActionRepeat again(std::move(ending), config);
  const int resets_before = ending_env->resets;
  EXPECT_THROW(again.Reset(3), std::runtime_error);
  EXPECT_EQ(ending_env->resets - resets_before, 11);
  EXPECT_EQ(ending_env->steps_taken, 22);
}

TEST(ActionRepeatTest, RejectsNullAndBadConfigs) {
  EXPECT_THROW(ActionRepeat(nullptr, Skip(1)), std::invalid_argument);
  EXPECT_THROW(ActionRepeat(MakeScripted(), Skip(0)), std::invalid_argument);
}

TEST(ActionRepeatTest, StepBeforeResetAndBadActionsThrow) {
  auto inner = MakeScripted();
  ScriptedImageEnv* scripted = inner.get();
  ActionRepeat env(std::move(inner), Skip(2));
  EXPECT_THROW(env.Step(DiscreteAction(0)), std::logic_error);
  EXPECT_THROW(env.image(), std::logic_error);
  env.Reset(0);
  EXPECT_THROW(env.Step(DiscreteAction(3)), std::invalid_argument);
  EXPECT_EQ(scripted->steps_taken, 0);
  EXPECT_EQ(Bytes(env.image()), kF0);
}

}  // namespace
}  // namespace rl::envs
