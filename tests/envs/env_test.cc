#include "envs/env.h"

#include <array>
#include <cstdint>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

namespace rl::envs {
namespace {

// An env whose native rendering is a 4x2 image: left half black, right half white.
class TwoToneEnv : public Env {
 public:
  const EnvSpec& spec() const override { return spec_; }
  void Reset(uint64_t) override {}
  void Reset() override {}
  StepResult Step(int) override { return {}; }
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

 private:
  EnvSpec spec_{"TwoTone", 1, 1, 10, 0};
  std::array<float, 1> observation_{};
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

TEST(EnvTest, DiscreteSpecsHaveNoContinuousActionsAndStepContinuousThrows) {
  TwoToneEnv env;
  EXPECT_EQ(env.spec().action_dim, 0);
  EXPECT_TRUE(env.spec().action_low.empty());
  EXPECT_TRUE(env.spec().action_high.empty());
  try {
    env.StepContinuous(std::array<float, 2>{0, 0});
    FAIL() << "expected std::logic_error";
  } catch (const std::logic_error& e) {
    EXPECT_EQ(std::string(e.what()), "discrete env");
  }
}

}  // namespace
}  // namespace rl::envs
