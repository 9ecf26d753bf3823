#include "evaluator/tsne_map.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include "envs/registry.h"
#include "nn/linear.h"
#include "nn/sequential.h"
#include "tests/common/temp_dir.h"

namespace rl::evaluator {
namespace {

constexpr char kCatchPixels[] = "Catch-v0+pixels(width=5,height=10,stack=2)";
constexpr char kPendulumPixels[] = "Pendulum-v1+pixels(width=8,height=8,stack=2)";

nn::Sequential Build(const std::string& arch, uint32_t seed) {
  std::mt19937 rng(seed);
  return nn::BuildFromArchitecture(arch, &rng);
}

TEST(TsneMapTest, TheLastHiddenLayerIsTheInputOfTheLastLinearLayerOrDuelingHead) {
  EXPECT_EQ(LastHiddenLayerIndex(Build("linear(4,8),relu,linear(8,2)", 1)), 2);
  EXPECT_EQ(
      LastHiddenLayerIndex(Build("conv2d(2,16,3,1,1,10,5),relu,flatten,dueling(800,64,3)", 1)), 3);
  // A TD3 actor: the layers after the last linear one (bounds) do not count.
  EXPECT_EQ(LastHiddenLayerIndex(Build("linear(4,8),relu,linear(8,1),bounded(1,-2,2)", 1)), 2);
  EXPECT_THROW(LastHiddenLayerIndex(Build("linear(4,2)", 1)), std::invalid_argument);
  EXPECT_THROW(LastHiddenLayerIndex(Build("relu", 1)), std::invalid_argument);
}

TEST(TsneMapTest, CollectsTheHiddenLayerTheGreedyValueAndTheFrameOfEveryState) {
  nn::Sequential net = Build("linear(100,16),relu,linear(16,3)", 4);
  const uint64_t seed = 500;
  // The hook comes after every step with the states kept so far (one a step here).
  std::vector<int> kept;
  const StateSamples s =
      CollectStates(&net, kCatchPixels, 100, seed, 0.99, [&](int n) { kept.push_back(n); });
  ASSERT_EQ(kept.size(), 100U);
  for (size_t i = 0; i < kept.size(); ++i) EXPECT_EQ(kept[i], static_cast<int>(i) + 1);
  ASSERT_EQ(s.activations.rows(), 16);
  ASSERT_EQ(s.activations.cols(), 100);
  ASSERT_EQ(s.values.size(), 100U);
  ASSERT_EQ(s.frames.size(), 100U * 10 * 5);
  EXPECT_FALSE(s.value_is_return);
  EXPECT_EQ(s.layer, 2);
  EXPECT_EQ(s.layer_description, "linear(16,3)");
  EXPECT_EQ(s.frame_height, 10);
  EXPECT_EQ(s.frame_width, 5);
  // Catch episodes last 9 steps: 11 whole episodes and the first state of a 12th.
  EXPECT_EQ(s.episodes, 12);

  // Replay the first episode by hand: relu(W x + b), max_a Q and the newest frame of each state.
  auto env = envs::MakeEnv(kCatchPixels);
  env->Reset(seed);
  for (int t = 0; t < 9; ++t) {
    const auto obs = env->observation();
    const nn::Matrix& q = net.Predict(obs.data(), static_cast<int>(obs.size()));
    Eigen::Index best = 0;
    const float max_q = q.col(0).maxCoeff(&best);
    EXPECT_FLOAT_EQ(static_cast<float>(s.values[static_cast<size_t>(t)]), max_q) << "step " << t;
    const nn::Matrix hidden = net.LayerInput(2);
    auto& first = dynamic_cast<nn::Linear&>(net.layer(0));
    const Eigen::Map<const Eigen::VectorXf> x(obs.data(), static_cast<Eigen::Index>(obs.size()));
    const Eigen::VectorXf by_hand = (first.weight() * x + first.bias()).cwiseMax(0.0f);
    EXPECT_LT((s.activations.col(t) - by_hand).cwiseAbs().maxCoeff(), 1e-5f) << "step " << t;
    EXPECT_EQ(s.activations.col(t), hidden.col(0));
    const auto frame = env->frame();
    EXPECT_TRUE(std::equal(frame.begin(), frame.end(), s.frames.begin() + 50 * t));
    const float action = static_cast<float>(best);
    env->Step(std::span<const float>(&action, 1));
  }
  // The next episode starts from the next seed.
  env->Reset(seed + 1);
  const auto frame = env->frame();
  EXPECT_TRUE(std::equal(frame.begin(), frame.end(), s.frames.begin() + 50 * 9));
}

TEST(TsneMapTest, ANetworkWithoutValuesIsColouredByTheDiscountedReturnThatFollowed) {
  nn::Sequential net = Build("linear(128,8),relu,linear(8,1),bounded(1,-2,2)", 6);
  const uint64_t seed = 900;
  const double gamma = 0.9;
  const StateSamples s = CollectStates(&net, kPendulumPixels, 100, seed, gamma);
  EXPECT_TRUE(s.value_is_return);
  ASSERT_EQ(s.values.size(), 100U);
  ASSERT_EQ(s.activations.rows(), 8);
  // Pendulum episodes last 200 steps (then the time limit): the first 100 states of one.
  EXPECT_EQ(s.episodes, 1);
  // Replay it: the return of step t is sum_k gamma^k r_{t+k} to the time limit.
  auto env = envs::MakeEnv(kPendulumPixels);
  env->Reset(seed);
  std::vector<double> rewards;
  for (;;) {
    const auto obs = env->observation();
    const float a =
        std::clamp(net.Predict(obs.data(), static_cast<int>(obs.size()))(0, 0), -2.0f, 2.0f);
    const envs::StepResult r = env->Step(std::span<const float>(&a, 1));
    rewards.push_back(r.reward);
    if (r.terminated || r.truncated) break;
  }
  ASSERT_EQ(rewards.size(), 200U);
  std::vector<double> returns(rewards.size());
  double g = 0;
  for (size_t t = rewards.size(); t-- > 0;) returns[t] = g = rewards[t] + gamma * g;
  for (size_t t : {size_t{0}, size_t{1}, size_t{50}, size_t{99}}) {
    EXPECT_NEAR(s.values[t], returns[t], 1e-9 * std::abs(returns[t]) + 1e-12) << "step " << t;
  }
}

TEST(TsneMapTest, RefusesFlatEnvsAndBadCounts) {
  nn::Sequential cartpole = Build("linear(4,8),relu,linear(8,2)", 2);
  EXPECT_THROW(CollectStates(&cartpole, "CartPole-v1", 100), std::invalid_argument);
  nn::Sequential net = Build("linear(100,16),relu,linear(16,3)", 4);
  EXPECT_THROW(CollectStates(&net, kCatchPixels, kTsneMapMinStates - 1), std::invalid_argument);
  EXPECT_THROW(CollectStates(&net, kCatchPixels, kTsneMapMaxStates + 1), std::invalid_argument);
  EXPECT_THROW(CollectStates(&net, kCatchPixels, 100, 0, 1.5), std::invalid_argument);
  // The network must fit the env.
  nn::Sequential wrong = Build("linear(99,16),relu,linear(16,3)", 4);
  EXPECT_THROW(CollectStates(&wrong, kCatchPixels, 100), std::invalid_argument);
}

TEST(TsneMapTest, ThumbnailsGoToTheLowestTheHighestAndTheQuantilesBetweenWithOtherFrames) {
  StateSamples s;
  s.frame_height = 1;
  s.frame_width = 1;
  // 11 states, values 0..10 in another order, each its own frame but the median's, which is the
  // lowest's.
  for (int i = 0; i < 11; ++i) {
    s.values.push_back(static_cast<double>((i * 7) % 11));  // a permutation of 0..10
    s.frames.push_back(static_cast<uint8_t>(i));
  }
  auto by_value = [&](double v) {
    return static_cast<int>(std::find(s.values.begin(), s.values.end(), v) - s.values.begin());
  };
  s.frames[static_cast<size_t>(by_value(5.0))] = s.frames[static_cast<size_t>(by_value(0.0))];
  const std::vector<int> picks = ThumbnailStates(s, 3);
  ASSERT_EQ(picks.size(), 3U);
  EXPECT_EQ(s.values[static_cast<size_t>(picks[0])], 0.0);
  EXPECT_EQ(s.values[static_cast<size_t>(picks[2])], 10.0);
  // The median (value 5) shows the frame of another state: a neighbour in value is taken.
  const double middle = s.values[static_cast<size_t>(picks[1])];
  EXPECT_TRUE(middle == 4.0 || middle == 6.0) << middle;
  EXPECT_EQ(ThumbnailStates(s, 20).size(), 11U);
  EXPECT_THROW(ThumbnailStates(s, 0), std::invalid_argument);
}

TEST(TsneMapTest, IdenticalActivationsMergeIntoOneStateWithTheMeanValue) {
  StateSamples s;
  s.frame_height = 1;
  s.frame_width = 2;
  s.activations.resize(3, 5);
  // States 0, 2 and 4 alike; 1 and 3 each their own.
  s.activations << 1, 0, 1, 0, 1,  //
      2, 5, 2, 5, 2,               //
      3, 1, 3, 0, 3;
  s.values = {1.0, 7.0, 2.0, 8.0, 6.0};
  s.frames = {10, 11, 20, 21, 30, 31, 40, 41, 50, 51};
  s.value_is_return = true;
  std::vector<int> counts;
  const StateSamples d = DistinctStates(s, &counts);
  ASSERT_EQ(d.activations.cols(), 3);
  EXPECT_EQ(counts, (std::vector<int>{3, 1, 1}));
  EXPECT_EQ(d.activations.col(0), s.activations.col(0));
  EXPECT_EQ(d.activations.col(1), s.activations.col(1));
  EXPECT_EQ(d.activations.col(2), s.activations.col(3));
  EXPECT_EQ(d.values, (std::vector<double>{3.0, 7.0, 8.0}));            // (1 + 2 + 6) / 3
  EXPECT_EQ(d.frames, (std::vector<uint8_t>{10, 11, 20, 21, 40, 41}));  // the first one's
  EXPECT_TRUE(d.value_is_return);
  s.values.pop_back();
  EXPECT_THROW(DistinctStates(s), std::invalid_argument);
}

TEST(TsneMapTest, WritesAPngWithTheScatterThumbnailsAndColourBar) {
  TempDir dir;
  nn::Sequential net = Build("linear(100,16),relu,linear(16,3)", 4);
  const StateSamples s = CollectStates(&net, kCatchPixels, 150, 1000, 0.99);
  TsneConfig c;
  c.iterations = 300;
  const std::string path = dir / "tsne.png";
  const TsneMapResult r = WriteTsneMap(s, c, path);
  EXPECT_EQ(r.states, 150);
  EXPECT_EQ(r.features, 16);
  // Catch repeats its states: fewer distinct ones, and a perplexity they allow.
  EXPECT_EQ(r.distinct, static_cast<int>(DistinctStates(s).activations.cols()));
  EXPECT_LT(r.distinct, 150);
  EXPECT_GE(r.distinct, kTsneMinPoints);
  EXPECT_LE(3 * r.perplexity, r.distinct - 1 + 1e-9);
  EXPECT_EQ(r.thumbnails.size(), static_cast<size_t>(kTsneMapThumbnails));
  EXPECT_LE(r.value_min, r.value_max);
  const cv::Mat page = cv::imread(path, cv::IMREAD_COLOR);
  ASSERT_FALSE(page.empty());
  EXPECT_EQ(page.cols, r.width);
  EXPECT_EQ(page.rows, r.height);
  // Nothing but the PNG in the folder (no temporary file left).
  int files = 0;
  for ([[maybe_unused]] const auto& entry : std::filesystem::directory_iterator(dir.path())) {
    ++files;
  }
  EXPECT_EQ(files, 1);
  // Samples that do not add up are refused.
  StateSamples broken = s;
  broken.values.pop_back();
  EXPECT_THROW(WriteTsneMap(broken, c, path), std::invalid_argument);
  broken = s;
  broken.values[7] = std::nan("");
  EXPECT_THROW(WriteTsneMap(broken, c, path), std::invalid_argument);
}

}  // namespace
}  // namespace rl::evaluator
