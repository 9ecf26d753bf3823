#include "evaluator/frame_grid.h"

#include <cmath>
#include <filesystem>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include "envs/registry.h"
#include "nn/sequential.h"
#include "tests/common/temp_dir.h"

namespace rl::evaluator {
namespace {

namespace fs = std::filesystem;

constexpr char kCatchPixels[] = "Catch-v0+pixels(width=5,height=10,stack=2)";

class FrameGridTest : public TempDirTest {};

// A network with random weights whose input is a Catch stack of 2 frames of 10 x 5.
nn::Sequential CatchNetwork() {
  std::mt19937 rng(3);
  return nn::MakeMlp(2 * 10 * 5, {16}, 3, &rng);
}

TEST_F(FrameGridTest, LaysOutOneRowPerEpisodeWithTheNetworksInputFrames) {
  nn::Sequential net = CatchNetwork();
  const std::string path = (dir_ / "frames.png").string();
  const uint64_t seed = 40;
  const FrameGridResult g = WriteFrameGrid(&net, kCatchPixels, seed, 3, 4, path);

  // Catch episodes last 9 steps: each row keeps 3 cells and the last one.
  EXPECT_EQ(g.episodes, 3);
  EXPECT_EQ(g.columns, 4);
  EXPECT_GE(g.mean_return, -1.0);
  EXPECT_LE(g.mean_return, 1.0);
  const cv::Mat page = cv::imread(path, cv::IMREAD_COLOR);
  ASSERT_FALSE(page.empty());
  EXPECT_EQ(page.cols, g.width);
  EXPECT_EQ(page.rows, g.height);
  EXPECT_EQ(g.height,
            kFrameGridGap + 3 * (kFrameGridLabelHeight + kFrameGridImageHeight + kFrameGridGap));
  // Only the PNG is left in the folder (no temporary file).
  int files = 0;
  for ([[maybe_unused]] const auto& entry : fs::directory_iterator(dir_)) ++files;
  EXPECT_EQ(files, 1);

  // The right image of the first cell of row 0 is the frame after Reset(seed), each pixel a block.
  auto replica = envs::MakeEnv(kCatchPixels);
  replica->Reset(seed);
  std::vector<uint8_t> rgb;
  int w = 0, h = 0;
  replica->Render(&rgb, &w, &h);
  const int left_width =
      static_cast<int>(std::lround(static_cast<double>(w) * kFrameGridImageHeight / h));
  const int x0 = kFrameGridGap + left_width + kFrameGridGap;
  const int y0 = kFrameGridGap + kFrameGridLabelHeight;
  const double block = static_cast<double>(kFrameGridImageHeight) / 10;  // rows of a frame
  const auto frame = replica->frame();
  int bright = 0;
  for (int r = 0; r < 10; ++r) {
    for (int c = 0; c < 5; ++c) {
      const cv::Vec3b& px = page.at<cv::Vec3b>(y0 + static_cast<int>((r + 0.5) * block),
                                               x0 + static_cast<int>((c + 0.5) * block));
      const uint8_t expected = frame[static_cast<size_t>(r) * 5 + c];
      EXPECT_EQ(px[0], expected) << "row " << r << " col " << c;
      EXPECT_EQ(px[1], expected);
      EXPECT_EQ(px[2], expected);
      bright += expected > 0 ? 1 : 0;
    }
  }
  EXPECT_GT(bright, 0);  // the ball and the paddle are in the frame

  // The left image is the camera as rendered: its top-left pixel is the render's.
  const cv::Vec3b camera = page.at<cv::Vec3b>(y0, kFrameGridGap);
  EXPECT_EQ(camera[2], rgb[0]);  // PNG pixels are BGR
  EXPECT_EQ(camera[1], rgb[1]);
  EXPECT_EQ(camera[0], rgb[2]);
}

TEST_F(FrameGridTest, IsTheSameForTheSameSeedAndNetwork) {
  nn::Sequential net = CatchNetwork();
  const std::string a = (dir_ / "a.png").string();
  const std::string b = (dir_ / "b.png").string();
  const FrameGridResult ga = WriteFrameGrid(&net, kCatchPixels, 7, 2, 5, a);
  const FrameGridResult gb = WriteFrameGrid(&net, kCatchPixels, 7, 2, 5, b);
  EXPECT_EQ(ga.mean_return, gb.mean_return);
  const cv::Mat pa = cv::imread(a), pb = cv::imread(b);
  ASSERT_EQ(pa.size(), pb.size());
  EXPECT_EQ(cv::norm(pa, pb, cv::NORM_INF), 0.0);
}

TEST_F(FrameGridTest, RefusesFlatEnvsMisfitNetworksAndEmptyGrids) {
  const std::string path = (dir_ / "never.png").string();
  std::mt19937 rng(1);
  nn::Sequential cartpole = nn::MakeMlp(4, {8}, 2, &rng);
  EXPECT_THROW(WriteFrameGrid(&cartpole, "CartPole-v1", 1, 2, 4, path), std::invalid_argument);
  EXPECT_THROW(WriteFrameGrid(&cartpole, kCatchPixels, 1, 2, 4, path), std::invalid_argument);
  nn::Sequential net = CatchNetwork();
  EXPECT_THROW(WriteFrameGrid(&net, kCatchPixels, 1, 0, 4, path), std::invalid_argument);
  EXPECT_THROW(WriteFrameGrid(&net, kCatchPixels, 1, 2, 1, path), std::invalid_argument);
  EXPECT_FALSE(fs::exists(path));
}

}  // namespace
}  // namespace rl::evaluator
