#include "evaluator/video.h"

#include <filesystem>
#include <fstream>
#include <random>

#include <gtest/gtest.h>
#include <opencv2/videoio.hpp>

#include "nn/sequential.h"
#include "tests/common/temp_dir.h"

namespace rl::evaluator {
namespace {

namespace fs = std::filesystem;

// A network that always pushes right: CartPole falls within a few dozen steps.
nn::Sequential PushesRight() {
  std::mt19937 rng(1);
  nn::Sequential net = nn::MakeMlp(4, {8}, 2, &rng);
  std::vector<float> flat;
  net.GetFlat(&flat);
  std::fill(flat.begin(), flat.end(), 0.0f);
  flat.back() = 1.0f;
  net.SetFlat(flat.data(), flat.size());
  return net;
}

class VideoTest : public TempDirTest {};

TEST_F(VideoTest, WritesAPlayableWebmOfOneGreedyEpisode) {
  const std::string path = (dir_ / "best.webm").string();
  nn::Sequential net = PushesRight();
  int ticks = 0;
  const VideoResult v =
      RecordGreedyVideo(&net, "CartPole-v1", 7, 120, 81, 30, path, [&] { ++ticks; });
  EXPECT_EQ(ticks, v.frames - 1);  // after every step (the first frame is the reset's)
  EXPECT_EQ(v.width, 120);
  EXPECT_EQ(v.height, 82);  // rounded up to even
  EXPECT_GT(v.frames, 5);
  EXPECT_LT(v.frames, 100);
  EXPECT_DOUBLE_EQ(v.episode_return, v.frames - 1);  // reward 1 per step
  EXPECT_FALSE(fs::exists(path + ".tmp.webm"));
  // A WebM file starts with the EBML magic number.
  std::ifstream in(path, std::ios::binary);
  unsigned char magic[4] = {};
  in.read(reinterpret_cast<char*>(magic), 4);
  EXPECT_EQ(magic[0], 0x1A);
  EXPECT_EQ(magic[1], 0x45);
  EXPECT_EQ(magic[2], 0xDF);
  EXPECT_EQ(magic[3], 0xA3);
  // It decodes back to the frames written, at the size written.
  cv::VideoCapture cap(path);
  ASSERT_TRUE(cap.isOpened());
  int frames = 0;
  cv::Mat f;
  while (cap.read(f)) {
    EXPECT_EQ(f.cols, 120);
    EXPECT_EQ(f.rows, 82);
    ++frames;
  }
  EXPECT_EQ(frames, v.frames);
}

// A stop during the episode (the tick throws) leaves neither the video nor its temporary file.
TEST_F(VideoTest, AStopDuringTheEpisodeLeavesNoFile) {
  const std::string path = (dir_ / "best.webm").string();
  nn::Sequential net = PushesRight();
  int ticks = 0;
  EXPECT_THROW(RecordGreedyVideo(&net, "CartPole-v1", 7, 120, 81, 30, path,
                                 [&] {
                                   if (++ticks == 3) throw Interrupted{};
                                 }),
               Interrupted);
  EXPECT_EQ(ticks, 3);
  EXPECT_FALSE(fs::exists(path));
  EXPECT_FALSE(fs::exists(path + ".tmp.webm"));
}

TEST_F(VideoTest, RefusesANetworkThatDoesNotFitTheEnv) {
  std::mt19937 rng(1);
  nn::Sequential net = nn::MakeMlp(3, {8}, 2, &rng);
  const std::string path = (dir_ / "never.webm").string();
  EXPECT_THROW(RecordGreedyVideo(&net, "CartPole-v1", 1, 64, 64, 30, path), std::invalid_argument);
  EXPECT_FALSE(fs::exists(path));
}

}  // namespace
}  // namespace rl::evaluator
