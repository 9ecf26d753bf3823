#include "envs/env.h"

#include <array>
#include <cmath>
#include <cstdint>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

namespace rl::envs {
namespace {

// An env whose native rendering is a 4x2 image: left half black, right half white.
// Its steps record the action and the step count; a step with index 1 throws.
class TwoToneEnv : public Env {
 public:
  explicit TwoToneEnv(EnvSpec spec = EnvSpec{"TwoTone", 1, 2, 10, 0}) : Env(std::move(spec)) {}
  std::span<const float> observation() const override { return observation_; }
  void Render(std::vector<uint8_t>* rgb, int* width, int* height) const override {
    *width = 4;
    *height = 2;
    rgb->assign(4 * 2 * 3, 0);
    for (int y = 0; y < 2; ++y) {
      for (int x = 2; x < 4; ++x) {
        for (int c = 0; c < 3; ++c) (*rgb)[(y * 4 + x) * 3 + c] = 255;
      }
    }
  }

  std::optional<uint64_t> last_seed;
  float last_action = -1;
  int64_t steps_seen = -1;

 private:
  void OnReset(std::optional<uint64_t> seed) override { last_seed = seed; }
  StepResult OnStep(std::span<const float> action) override {
    last_action = action[0];
    steps_seen = elapsed_steps();
    if (ActionIndex(action) == 1) throw std::runtime_error("scripted failure");
    return {.reward = 1};
  }

  std::array<float, 1> observation_{};
};

// A continuous env of two dimensions in [-1, 1] with TwoToneEnv's picture; its steps record the
// action.
EnvSpec BoxSpec() {
  EnvSpec spec{"Box", 1, 0, 10, 0};
  spec.action_dim = 2;
  spec.action_low = {-1, -1};
  spec.action_high = {1, 1};
  return spec;
}

class BoxEnv : public TwoToneEnv {
 public:
  BoxEnv() : TwoToneEnv(BoxSpec()) {}

  std::vector<float> last_box_action;

 private:
  StepResult OnStep(std::span<const float> action) override {
    last_box_action.assign(action.begin(), action.end());
    return {};
  }
};

TEST(EnvTest, DefaultRenderSizedAveragesTheNativeImage) {
  TwoToneEnv env;
  std::vector<uint8_t> rgb;
  // 4x2 -> 2x1: each output pixel covers one colour.
  env.RenderSized(2, 1, &rgb);
  EXPECT_EQ(rgb, (std::vector<uint8_t>{0, 0, 0, 255, 255, 255}));
  // 4x2 -> 1x1: half black, half white.
  env.RenderSized(1, 1, &rgb);
  EXPECT_EQ(rgb, (std::vector<uint8_t>{128, 128, 128}));
  // 4x2 -> 8x2: each source pixel doubles.
  env.RenderSized(8, 2, &rgb);
  ASSERT_EQ(rgb.size(), 8u * 2u * 3u);
  EXPECT_EQ(rgb[3 * 3], 0);
  EXPECT_EQ(rgb[4 * 3], 255);
}

TEST(EnvTest, DefaultRenderSizedRejectsEmptySizes) {
  TwoToneEnv env;
  std::vector<uint8_t> rgb;
  EXPECT_THROW(env.RenderSized(0, 1, &rgb), std::invalid_argument);
  EXPECT_THROW(env.RenderSized(3, -1, &rgb), std::invalid_argument);
}

TEST(EnvTest, DiscreteSpecsHaveNoContinuousActions) {
  TwoToneEnv env;
  EXPECT_EQ(env.spec().action_dim, 0);
  EXPECT_EQ(env.spec().action_width(), 1);
  EXPECT_TRUE(env.spec().action_low.empty());
  EXPECT_TRUE(env.spec().action_high.empty());
}

TEST(EnvTest, StepChecksTheActionBeforeTheEpisode) {
  TwoToneEnv env;
  // A bad action is refused first, naming the env; then a missing Reset.
  try {
    env.Step(std::array<float, 2>{0, 0});
    FAIL() << "expected std::invalid_argument";
  } catch (const std::invalid_argument& e) {
    EXPECT_EQ(std::string(e.what()), "TwoTone: action of the wrong width (got [0, 0])");
  }
  EXPECT_THROW(env.Step(DiscreteAction(2)), std::invalid_argument);
  EXPECT_THROW(env.Step(DiscreteAction(-1)), std::invalid_argument);
  EXPECT_THROW(env.Step(std::array<float, 1>{0.5f}), std::invalid_argument);
  EXPECT_THROW(env.Step(std::array<float, 1>{NAN}), std::invalid_argument);
  EXPECT_THROW(env.Step(DiscreteAction(0)), std::logic_error);
  EXPECT_FALSE(env.started());
  EXPECT_EQ(env.last_action, -1);
}

TEST(EnvTest, ResetForwardsTheSeedAndRestartsTheCount) {
  TwoToneEnv env;
  env.Reset(7);
  EXPECT_EQ(env.last_seed, std::optional<uint64_t>(7));
  EXPECT_TRUE(env.started());
  EXPECT_EQ(env.Step(DiscreteAction(0)).reward, 1);
  EXPECT_EQ(env.steps_seen, 1);  // OnStep sees the step it takes counted.
  env.Step(DiscreteAction(0));
  EXPECT_EQ(env.elapsed_steps(), 2);
  env.Reset();
  EXPECT_EQ(env.last_seed, std::nullopt);
  EXPECT_EQ(env.elapsed_steps(), 0);
}

TEST(EnvTest, AStepThatThrowsIsNotCounted) {
  TwoToneEnv env;
  env.Reset(0);
  env.Step(DiscreteAction(0));
  EXPECT_THROW(env.Step(DiscreteAction(1)), std::runtime_error);
  EXPECT_EQ(env.last_action, 1.0f);
  EXPECT_EQ(env.elapsed_steps(), 1);
  EXPECT_THROW(env.Step(DiscreteAction(5)), std::invalid_argument);
  EXPECT_EQ(env.elapsed_steps(), 1);
}

TEST(EnvTest, ContinuousStepsPassValuesOutOfBoundsAndRefuseNaN) {
  BoxEnv env;
  env.Reset(0);
  // The env clips: out-of-bounds and infinite values reach it unchanged.
  env.Step(std::array<float, 2>{3, -INFINITY});
  EXPECT_EQ(env.last_box_action, (std::vector<float>{3, -INFINITY}));
  EXPECT_THROW(env.Step(std::array<float, 2>{0, NAN}), std::invalid_argument);
  EXPECT_THROW(env.Step(DiscreteAction(0)), std::invalid_argument);
  EXPECT_EQ(env.elapsed_steps(), 1);
}

}  // namespace
}  // namespace rl::envs
