#include "envs/image/frame_processor.h"

#include <cstdint>
#include <memory>
#include <span>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "tests/envs/image/scripted_image_env.h"

namespace rl::envs {
namespace {

using testing::GrayRgb;
using testing::GrayShape;
using testing::RgbShape;
using testing::ScriptedImageEnv;

std::vector<uint8_t> Bytes(std::span<const uint8_t> image) { return {image.begin(), image.end()}; }

// A FrameProcessor over a scripted source that shows `frame` (of `shape`) after Reset.
std::unique_ptr<FrameProcessor> Process(ImageShape shape, std::vector<uint8_t> frame,
                                        const ImagePipelineConfig& config) {
  auto source = std::make_unique<ScriptedImageEnv>(
      shape, std::vector<std::vector<uint8_t>>{std::move(frame)});
  auto processor = std::make_unique<FrameProcessor>(std::move(source), config);
  processor->Reset(0);
  return processor;
}

// A config that keeps the cropped size.
ImagePipelineConfig Keep() {
  ImagePipelineConfig config;
  config.width = 0;
  config.height = 0;
  return config;
}

ImagePipelineConfig ResizeTo(int width, int height) {
  ImagePipelineConfig config;
  config.width = width;
  config.height = height;
  return config;
}

TEST(FrameProcessorTest, ConvertsRgbToGrayWithTheItuWeights) {
  // Y = 0.299 R + 0.587 G + 0.114 B, rounded to nearest:
  //   (255, 0, 0)      -> 76.245  -> 76
  //   (0, 255, 0)      -> 149.685 -> 150
  //   (0, 0, 255)      -> 29.07   -> 29
  //   (255, 255, 255)  -> 255
  //   (10, 20, 30)     -> 2.99 + 11.74 + 3.42   = 18.15  -> 18
  //   (100, 150, 200)  -> 29.9 + 88.05 + 22.8   = 140.75 -> 141
  const std::vector<uint8_t> rgb = {255, 0,   0,   0,  255, 0,  0,   0,   255,  //
                                    255, 255, 255, 10, 20,  30, 100, 150, 200};
  const auto env = Process(RgbShape(3, 2), rgb, Keep());
  EXPECT_EQ(env->image_shape(), GrayShape(3, 2));
  EXPECT_EQ(Bytes(env->image()), (std::vector<uint8_t>{76, 150, 29, 255, 18, 141}));
}

TEST(FrameProcessorTest, CropsEachSide) {
  // 6x4 frame with pixel value 10 * row + column (gray, so the conversion keeps it).
  const std::vector<uint8_t> rgb = GrayRgb({0,  1,  2,  3,  4,  5,   //
                                            10, 11, 12, 13, 14, 15,  //
                                            20, 21, 22, 23, 24, 25,  //
                                            30, 31, 32, 33, 34, 35});
  ImagePipelineConfig config = Keep();
  config.crop_top = 1;
  config.crop_bottom = 1;
  config.crop_left = 2;
  config.crop_right = 1;
  const auto env = Process(RgbShape(6, 4), rgb, config);
  // Rows 1-2, columns 2-4.
  EXPECT_EQ(env->image_shape(), GrayShape(3, 2));
  EXPECT_EQ(Bytes(env->image()), (std::vector<uint8_t>{12, 13, 14, 22, 23, 24}));
}

TEST(FrameProcessorTest, AreaResizeAveragesEachBlock) {
  // 4x4 -> 2x2: each output pixel is the mean of a 2x2 block.
  const std::vector<uint8_t> rgb = GrayRgb({10, 20, 50, 70,   //
                                            30, 40, 90, 110,  //
                                            0, 0, 255, 255,   //
                                            4, 8, 255, 255});
  const auto env = Process(RgbShape(4, 4), rgb, ResizeTo(2, 2));
  EXPECT_EQ(env->image_shape(), GrayShape(2, 2));
  // (10+20+30+40)/4 = 25, (50+70+90+110)/4 = 80, (0+0+4+8)/4 = 3, 255.
  EXPECT_EQ(Bytes(env->image()), (std::vector<uint8_t>{25, 80, 3, 255}));
}

TEST(FrameProcessorTest, AreaResizeWeighsPartlyCoveredPixels) {
  // 3x1 -> 2x1: output pixel 0 covers source [0, 1.5): (30 * 1 + 60 * 0.5) / 1.5 = 40; pixel 1
  // covers [1.5, 3): (60 * 0.5 + 90 * 1) / 1.5 = 80.
  const auto env = Process(RgbShape(3, 1), GrayRgb({30, 60, 90}), ResizeTo(2, 1));
  EXPECT_EQ(Bytes(env->image()), (std::vector<uint8_t>{40, 80}));
}

TEST(FrameProcessorTest, CropsBeforeResizing) {
  // The 4x4 block of AreaResizeAveragesEachBlock with a 255 border column on each side and a 255
  // row on top; the crop removes them, the resize gives the same 2x2.
  const std::vector<uint8_t> rgb = GrayRgb({255, 255, 255, 255, 255, 255,  //
                                            255, 10,  20,  50,  70,  255,  //
                                            255, 30,  40,  90,  110, 255,  //
                                            255, 0,   0,   255, 255, 255,  //
                                            255, 4,   8,   255, 255, 255});
  ImagePipelineConfig config = ResizeTo(2, 2);
  config.crop_top = 1;
  config.crop_left = 1;
  config.crop_right = 1;
  const auto env = Process(RgbShape(6, 5), rgb, config);
  EXPECT_EQ(Bytes(env->image()), (std::vector<uint8_t>{25, 80, 3, 255}));
}

TEST(FrameProcessorTest, ProcessesEveryStep) {
  // Reset shows a black 2x2 frame, the first step a white one; the output is their 1x1 mean.
  auto source = std::make_unique<ScriptedImageEnv>(
      RgbShape(2, 2),
      std::vector<std::vector<uint8_t>>{GrayRgb({0, 0, 0, 0}), GrayRgb({255, 255, 200, 201})},
      std::vector<testing::ScriptedStep>{{.reward = 1.5, .terminated = true}});
  FrameProcessor env(std::move(source), ResizeTo(1, 1));
  env.Reset(0);
  EXPECT_EQ(Bytes(env.image()), std::vector<uint8_t>{0});
  const StepResult r = env.Step(DiscreteAction(0));
  EXPECT_EQ(r.reward, 1.5);
  EXPECT_TRUE(r.terminated);
  // (255 + 255 + 200 + 201) / 4 = 227.75 -> 228.
  EXPECT_EQ(Bytes(env.image()), std::vector<uint8_t>{228});
  // spec() and observation() are the wrapped env's.
  EXPECT_EQ(env.spec().id, "Scripted-v0");
  EXPECT_EQ(env.spec().observation_size, 1);
  EXPECT_EQ(env.observation()[0], 1.0f);
}

TEST(FrameProcessorTest, RejectsCropsThatLeaveNothingAndNonRgbInput) {
  auto source = [] {
    return std::make_unique<ScriptedImageEnv>(
        RgbShape(4, 3),
        std::vector<std::vector<uint8_t>>{GrayRgb({0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0})});
  };
  ImagePipelineConfig config = Keep();
  config.crop_left = 2;
  config.crop_right = 2;
  try {
    FrameProcessor env(source(), config);
    FAIL() << "expected std::invalid_argument";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("crop_left + crop_right"), std::string::npos) << e.what();
  }
  config = Keep();
  config.crop_top = 3;
  EXPECT_THROW(FrameProcessor(source(), config), std::invalid_argument);
  // Leaving one pixel is fine.
  config.crop_top = 2;
  config.crop_left = 3;
  EXPECT_EQ(FrameProcessor(source(), config).image_shape(), GrayShape(1, 1));

  auto gray = std::make_unique<ScriptedImageEnv>(GrayShape(2, 2),
                                                 std::vector<std::vector<uint8_t>>{{0, 0, 0, 0}});
  EXPECT_THROW(FrameProcessor(std::move(gray), Keep()), std::invalid_argument);
  EXPECT_THROW(FrameProcessor(nullptr, Keep()), std::invalid_argument);
}

TEST(FrameProcessorTest, ImageBeforeResetThrows) {
  FrameProcessor env(std::make_unique<ScriptedImageEnv>(
                         RgbShape(1, 1), std::vector<std::vector<uint8_t>>{{1, 2, 3}}),
                     Keep());
  EXPECT_THROW(env.image(), std::logic_error);
}

}  // namespace
}  // namespace rl::envs
