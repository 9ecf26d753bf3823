#include "envs/image/pixel_env.h"

#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "envs/catch.h"
#include "envs/registry.h"
#include "tests/envs/image/scripted_image_env.h"
#include "tests/envs/image/span_vectors.h"

namespace rl::envs {
namespace {

using testing::GrayRgb;
using testing::RgbShape;
using testing::ScriptedImageEnv;
using testing::ScriptedStep;

// Expects config.Validate() to throw std::invalid_argument with `field` in the message.
void ExpectInvalid(const std::function<void(ImagePipelineConfig&)>& change, const char* field) {
  ImagePipelineConfig config;
  change(config);
  try {
    config.Validate();
    ADD_FAILURE() << "expected std::invalid_argument naming " << field;
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find(field), std::string::npos) << e.what();
  }
}

TEST(ImagePipelineConfigTest, DefaultsAreValid) {
  const ImagePipelineConfig config;
  EXPECT_NO_THROW(config.Validate());
  EXPECT_EQ(config.width, 84);
  EXPECT_EQ(config.height, 84);
  EXPECT_EQ(config.stack, 4);
  EXPECT_EQ(config.frame_skip, 1);
  EXPECT_TRUE(config.max_pool);
  EXPECT_FALSE(config.clip_rewards);
}

TEST(ImagePipelineConfigTest, ValidateNamesTheBadField) {
  ExpectInvalid([](ImagePipelineConfig& c) { c.render_width = 10; }, "render_width");
  ExpectInvalid([](ImagePipelineConfig& c) { c.render_height = 10; }, "render_height");
  ExpectInvalid(
      [](ImagePipelineConfig& c) {
        c.render_width = -1;
        c.render_height = -1;
      },
      "render_width");
  ExpectInvalid([](ImagePipelineConfig& c) { c.frame_skip = 0; }, "frame_skip");
  ExpectInvalid([](ImagePipelineConfig& c) { c.crop_top = -1; }, "crop_top");
  ExpectInvalid([](ImagePipelineConfig& c) { c.crop_bottom = -1; }, "crop_bottom");
  ExpectInvalid([](ImagePipelineConfig& c) { c.crop_left = -1; }, "crop_left");
  ExpectInvalid([](ImagePipelineConfig& c) { c.crop_right = -1; }, "crop_right");
  ExpectInvalid(
      [](ImagePipelineConfig& c) {
        c.render_width = 10;
        c.render_height = 10;
        c.crop_left = 5;
        c.crop_right = 5;
      },
      "crop_left + crop_right");
  ExpectInvalid(
      [](ImagePipelineConfig& c) {
        c.render_width = 10;
        c.render_height = 10;
        c.crop_top = 10;
      },
      "crop_top + crop_bottom");
  ExpectInvalid([](ImagePipelineConfig& c) { c.width = 0; }, "width");
  ExpectInvalid([](ImagePipelineConfig& c) { c.height = -84; }, "height");
  ExpectInvalid([](ImagePipelineConfig& c) { c.stack = 0; }, "stack");
}

// A scripted 4x2 env of gray pixels (so the grayscale value is the pixel's value), rewards of 1.5
// per inner step and -4 on the third, which terminates.
std::unique_ptr<ScriptedImageEnv> MakeScripted() {
  std::vector<std::vector<uint8_t>> frames = {
      GrayRgb({0, 0, 51, 51,  //
               0, 0, 51, 51}),
      GrayRgb({204, 0, 0, 0,  //
               0, 0, 0, 0}),
      GrayRgb({0, 204, 0, 0,  //
               0, 0, 102, 102}),
      GrayRgb({255, 255, 255, 255,  //
               255, 255, 51, 51}),
  };
  std::vector<ScriptedStep> steps = {
      {.reward = 1.5}, {.reward = 1.5}, {.reward = -4, .terminated = true}};
  return std::make_unique<ScriptedImageEnv>(RgbShape(4, 2), std::move(frames), std::move(steps));
}

// frame_skip 2 with max-pooling, a 2x1 output (each pixel the mean of a 2x2 block), 2 frames,
// clipped rewards.
ImagePipelineConfig ScriptedConfig() {
  ImagePipelineConfig config;
  config.frame_skip = 2;
  config.width = 2;
  config.height = 1;
  config.stack = 2;
  config.clip_rewards = true;
  return config;
}

TEST(MakePixelEnvTest, SpecKeepsTheInnerIdActionsAndThresholdAndDescribesTheFrames) {
  auto env = MakePixelEnv(MakeScripted(), ScriptedConfig());
  EXPECT_EQ(env->spec().id, "Scripted-v0");
  EXPECT_EQ(env->spec().num_actions, 3);
  EXPECT_EQ(env->spec().reward_threshold, 2.5);
  EXPECT_EQ(env->spec().max_episode_steps, 5);  // ceil(10 / 2).
  EXPECT_EQ(env->spec().frame_height, 1);
  EXPECT_EQ(env->spec().frame_width, 2);
  EXPECT_EQ(env->spec().frame_stack, 2);
  EXPECT_EQ(env->spec().observation_size, 4);
  EXPECT_EQ(env->spec().action_dim, 0);

  ImagePipelineConfig atari;  // 84x84x4, frame_skip 4.
  atari.frame_skip = 4;
  auto big = MakePixelEnv(MakeScripted(), atari);
  EXPECT_EQ(big->spec().max_episode_steps, 3);  // ceil(10 / 4).
  EXPECT_EQ(big->spec().observation_size, 4 * 84 * 84);
}

TEST(MakePixelEnvTest, RunsTheWholePipeline) {
  auto env = MakePixelEnv(MakeScripted(), ScriptedConfig());
  env->Reset(3);
  // Reset frame: left block (0 0 / 0 0) -> 0, right block (51 51 / 51 51) -> 51, stacked twice.
  EXPECT_EQ(Bytes(env->frame()), (std::vector<uint8_t>{0, 51}));
  EXPECT_EQ(Floats(env->observation()), (std::vector<float>{0, 0.2f, 0, 0.2f}));

  // Inner steps 1 and 2: reward 1.5 + 1.5 = 3, clipped to 1. Max of frames 1 and 2 is
  // (204 204 0 0 / 0 0 102 102): left block (204 + 204 + 0 + 0) / 4 = 102, right block
  // (0 + 0 + 102 + 102) / 4 = 51.
  StepResult r = env->Step(DiscreteAction(1));
  EXPECT_EQ(r.reward, 1.0);
  EXPECT_FALSE(r.terminated);
  EXPECT_EQ(Bytes(env->frame()), (std::vector<uint8_t>{102, 51}));
  EXPECT_EQ(Floats(env->observation()), (std::vector<float>{0, 0.2f, 0.4f, 0.2f}));

  // Inner step 3 terminates: reward -4 clipped to -1, frame 3 alone: left block 255, right block
  // (255 + 255 + 51 + 51) / 4 = 153.
  r = env->Step(DiscreteAction(1));
  EXPECT_EQ(r.reward, -1.0);
  EXPECT_TRUE(r.terminated);
  EXPECT_EQ(Bytes(env->frame()), (std::vector<uint8_t>{255, 153}));
  EXPECT_EQ(Floats(env->observation()), (std::vector<float>{0.4f, 0.2f, 1.0f, 0.6f}));

  // A new episode starts from its own first frame only.
  env->Reset();
  EXPECT_EQ(Floats(env->observation()), (std::vector<float>{0, 0.2f, 0, 0.2f}));
}

TEST(MakePixelEnvTest, RenderForwardsToTheInnerEnv) {
  auto env = MakePixelEnv(MakeScripted(), ScriptedConfig());
  env->Reset(0);
  std::vector<uint8_t> rgb;
  int width = 0;
  int height = 0;
  env->Render(&rgb, &width, &height);
  EXPECT_EQ(width, 4);
  EXPECT_EQ(height, 2);
  EXPECT_EQ(rgb, GrayRgb({0, 0, 51, 51, 0, 0, 51, 51}));
  env->RenderSized(2, 1, &rgb);
  EXPECT_EQ(rgb, GrayRgb({0, 51}));
}

TEST(MakePixelEnvTest, RejectsNullEnvsAndBadConfigs) {
  EXPECT_THROW(MakePixelEnv(nullptr, {}), std::invalid_argument);
  ImagePipelineConfig config;
  config.stack = 0;
  EXPECT_THROW(MakePixelEnv(MakeScripted(), config), std::invalid_argument);
  // A crop that leaves nothing of the 4x2 native frame.
  config = ImagePipelineConfig{};
  config.crop_top = 1;
  config.crop_bottom = 1;
  EXPECT_THROW(MakePixelEnv(MakeScripted(), config), std::invalid_argument);
}

// A continuous env goes through the whole pipeline: its actions reach it through every wrapper,
// repeated, and the frames are those of the states they lead to.
TEST(MakePixelEnvTest, ContinuousEnvsStepThroughEveryWrapper) {
  ImagePipelineConfig config;
  config.frame_skip = 2;
  config.width = config.height = 24;
  config.stack = 2;
  auto pixel = MakePixelEnv(MakeEnv("LunarLanderContinuous-v3"), config);
  auto plain = MakeEnv("LunarLanderContinuous-v3");
  EXPECT_TRUE(pixel->spec().continuous());
  EXPECT_EQ(pixel->spec().action_dim, 2);
  EXPECT_EQ(pixel->spec().max_episode_steps, 500);
  pixel->Reset(5);
  plain->Reset(5);
  const float action[] = {1.0f, -0.7f};
  double plain_reward = 0;
  for (int k = 0; k < 2; ++k) plain_reward += plain->Step(action).reward;
  const StepResult r = pixel->Step(action);
  EXPECT_DOUBLE_EQ(r.reward, plain_reward);
  EXPECT_THROW(pixel->Step(DiscreteAction(0)), std::logic_error);
}

// The pixels of a grayscale frame of `width` columns that are 255, as (x, y); all others must be 0.
std::vector<std::pair<int, int>> BrightPixels(std::span<const uint8_t> frame, int width) {
  std::vector<std::pair<int, int>> bright;
  for (int i = 0; i < static_cast<int>(frame.size()); ++i) {
    if (frame[i] == 255) {
      bright.emplace_back(i % width, i / width);
    } else {
      EXPECT_EQ(frame[i], 0) << "pixel " << i % width << "," << i / width;
    }
  }
  return bright;
}

// The pixels of the cells (row, column) of a grid of `cell`-pixel squares, in row-major order.
std::vector<std::pair<int, int>> CellPixels(int cell, int width,
                                            const std::vector<std::pair<int, int>>& cells) {
  std::vector<bool> lit;
  const int height = Catch::kRows * cell;
  lit.assign(static_cast<std::size_t>(width) * static_cast<std::size_t>(height), false);
  for (const auto& [row, column] : cells) {
    for (int y = row * cell; y < (row + 1) * cell; ++y) {
      for (int x = column * cell; x < (column + 1) * cell; ++x) {
        const int at = y * width + x;
        lit[static_cast<std::size_t>(at)] = true;
      }
    }
  }
  std::vector<std::pair<int, int>> pixels;
  for (int i = 0; i < width * height; ++i) {
    if (lit[static_cast<std::size_t>(i)]) pixels.emplace_back(i % width, i / width);
  }
  return pixels;
}

// Resets a pixel Catch env with `seed` and returns the ball's column, or -1 if its first frame
// shows no ball. The frame (a grid of `cell`-pixel squares, `width` pixels wide) must show only
// the ball in row 0 and the paddle in column 2.
int ResetAndFindTheBall(Env* env, uint64_t seed, int cell, int width) {
  env->Reset(seed);
  const std::vector<std::pair<int, int>> first = BrightPixels(env->frame(), width);
  if (first.empty()) return -1;
  const int ball = first.front().first / cell;
  EXPECT_EQ(first, CellPixels(cell, width, {{0, ball}, {9, 2}}));
  return ball;
}

TEST(MakePixelEnvTest, CatchAtItsNativeSizeShowsTheBallAndPaddleCells) {
  ImagePipelineConfig config;
  config.width = 0;
  config.height = 0;
  config.stack = 2;
  auto env = MakePixelEnv(std::make_unique<Catch>(), config);
  EXPECT_EQ(env->spec().frame_width, 40);
  EXPECT_EQ(env->spec().frame_height, 80);
  EXPECT_EQ(env->spec().observation_size, 2 * 40 * 80);
  EXPECT_EQ(env->spec().id, "Catch-v0");
  // Which column the ball is in: the bright pixels of row 0 (8 per cell).
  const int ball = ResetAndFindTheBall(env.get(), 11, 8, 40);
  ASSERT_GE(ball, 0) << "no ball in the first frame";
  // Left: paddle to column 1, ball to row 1.
  env->Step(DiscreteAction(0));
  EXPECT_EQ(BrightPixels(env->frame(), 40), CellPixels(8, 40, {{1, ball}, {9, 1}}));
}

TEST(MakePixelEnvTest, CatchResizedTo20By40ShowsTheCellsAtHalfSize) {
  ImagePipelineConfig config;
  config.width = 20;
  config.height = 40;
  config.frame_skip = 2;
  auto env = MakePixelEnv(MakeEnv("Catch-v0"), config);
  EXPECT_EQ(env->spec().max_episode_steps, 5);  // ceil(9 / 2).
  // Each cell is a 4x4 square of 255: the area mean of a uniform 8x8 cell.
  const int ball = ResetAndFindTheBall(env.get(), 5, 4, 20);
  ASSERT_GE(ball, 0) << "no ball in the first frame";
  // Two inner steps to the right. The frame is the max of the two raw frames, so it shows both
  // positions: the ball in rows 1 and 2, the paddle in columns 3 and 4.
  env->Step(DiscreteAction(2));
  EXPECT_EQ(BrightPixels(env->frame(), 20),
            CellPixels(4, 20, {{1, ball}, {2, ball}, {9, 3}, {9, 4}}));
  // Steps 2-4 take inner steps 3-8; step 5 takes only inner step 9, which ends the episode.
  for (int t = 2; t <= 4; ++t)
    EXPECT_FALSE(env->Step(DiscreteAction(1)).terminated) << "step " << t;
  const StepResult last = env->Step(DiscreteAction(1));
  EXPECT_TRUE(last.terminated);
  EXPECT_EQ(last.reward, ball == 4 ? 1.0 : -1.0);
}

}  // namespace
}  // namespace rl::envs
