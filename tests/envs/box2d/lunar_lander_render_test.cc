#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <vector>

#include <gtest/gtest.h>

#include "envs/box2d/lunar_lander.h"
#include "envs/raster.h"
#include "envs/registry.h"
#include "tests/envs/image_testing.h"

namespace rl::envs {
namespace {

constexpr Rgb kLanderFill{128, 102, 230};
constexpr Rgb kLanderOutline{77, 77, 128};
constexpr Rgb kFlag{204, 204, 0};

Image RenderAt(LunarLander& env, const LanderKinematics& k) {
  env.SetLanderKinematics(k);
  return Rendered(env);
}

TEST(LunarLanderRenderTest, ImageIs600By400WithBlackSkyAndWhiteGround) {
  LunarLander env;
  env.Reset(1);
  const Image image = RenderAt(env, LanderKinematics{.x = 4, .y = 10});
  EXPECT_EQ(image.width, 600);
  EXPECT_EQ(image.height, 400);
  ASSERT_EQ(image.rgb.size(), 600u * 400u * 3u);
  // The sky reaches the top edge; the ground fills the bottom rows.
  for (int x = 0; x < 600; x += 7) {
    ASSERT_EQ(image.at(x, 0), kBlack) << x;
    ASSERT_EQ(image.at(x, 399), kWhite) << x;
  }
  // The pad is at 0.99 * 100 = 99 px from the bottom: row 301 in the image.
  EXPECT_EQ(image.at(300, 296), kBlack);
  EXPECT_EQ(image.at(300, 306), kWhite);
  // Elsewhere the terrain line follows the terrain points.
  const double y0 = env.terrain_y()[0] * 30;
  EXPECT_EQ(image.at(1, static_cast<int>(400 - y0) - 3), kBlack);
  EXPECT_EQ(image.at(1, static_cast<int>(400 - y0) + 3), kWhite);
}

TEST(LunarLanderRenderTest, FlagsStandAtBothEndsOfThePad) {
  LunarLander env;
  env.Reset(1);
  const Image image = RenderAt(env, LanderKinematics{.x = 10, .y = 10});
  // Poles: columns 240 and 360, from 100 to 150 px above the bottom (rows 250 to 299).
  for (int x : {240, 360}) {
    EXPECT_EQ(image.at(x, 280), kWhite) << x;
    EXPECT_EQ(image.at(x, 270), kWhite) << x;
    EXPECT_EQ(image.at(x - 2, 270), kBlack) << x;
    EXPECT_EQ(image.at(x, 245), kBlack) << x;  // Above the pole's top.
    // The flag hangs to the right of the pole's top.
    EXPECT_EQ(image.at(x + 5, 255), kFlag) << x;
    EXPECT_EQ(image.at(x - 5, 255), kBlack) << x;
  }
  // Two triangles of 25 x 10 px: about 125 px each.
  const Blob flags = FindColor(image, kFlag);
  EXPECT_NEAR(flags.count, 250, 30);
  EXPECT_NEAR(flags.mean_x, 300 + 25.0 / 3, 2);
}

TEST(LunarLanderRenderTest, LanderAndLegsAreDrawnInTheirColours) {
  LunarLander env;
  env.Reset(1);
  const Image image = RenderAt(env, LanderKinematics{.x = 10, .y = 10});
  // The hull is 0.963 m^2 and the legs 2 x 0.071 m^2: about 995 px at 30 px per metre, part of it
  // under the outline.
  const Blob fill = FindColor(image, kLanderFill);
  const Blob outline = FindColor(image, kLanderOutline);
  EXPECT_GT(fill.count, 600);
  EXPECT_LT(fill.count + outline.count, 1200);
  EXPECT_GT(outline.count, 150);
  // Centred on the lander: x = 300 px, y = 400 - 300 = 100 (the hull's centroid is 3 px above
  // the origin, the legs hang 10 px below).
  EXPECT_NEAR(fill.mean_x, 300, 2);
  EXPECT_NEAR(fill.mean_y, 100, 5);
  EXPECT_EQ(image.at(300, 100), kLanderFill);
}

TEST(LunarLanderRenderTest, LanderPixelsMoveWithTheLander) {
  LunarLander env;
  env.Reset(2);
  const Blob a = FindColor(RenderAt(env, LanderKinematics{.x = 6, .y = 9}), kLanderFill);
  const Blob right = FindColor(RenderAt(env, LanderKinematics{.x = 12, .y = 9}), kLanderFill);
  const Blob up = FindColor(RenderAt(env, LanderKinematics{.x = 6, .y = 11}), kLanderFill);
  // 6 m right is 180 px right; 2 m up is 60 px up in the image.
  EXPECT_NEAR(right.mean_x - a.mean_x, 180, 0.5);
  EXPECT_NEAR(right.mean_y, a.mean_y, 0.5);
  EXPECT_NEAR(up.mean_y - a.mean_y, -60, 0.5);
  EXPECT_NEAR(up.mean_x, a.mean_x, 0.5);
  EXPECT_NEAR(right.count, a.count, a.count / 20.0);

  // Tilting by 90 degrees turns the wide hull upright: the pixels spread vertically.
  const Image tilted = RenderAt(env, LanderKinematics{.x = 6, .y = 9, .angle = 1.5707963});
  int rows = 0;
  int cols = 0;
  for (int y = 0; y < 400; ++y) {
    for (int x = 0; x < 600; ++x) {
      if (tilted.at(x, y) == kLanderFill) {
        rows += x == static_cast<int>(a.mean_x);
        cols += y == static_cast<int>(a.mean_y);
      }
    }
  }
  EXPECT_GT(rows, cols);
}

TEST(LunarLanderRenderTest, RenderSizedScalesThePicture) {
  LunarLander env;
  env.Reset(1);
  env.SetLanderKinematics(LanderKinematics{.x = 10, .y = 10});
  const Image small = RenderedSized(env, 300, 200);
  ASSERT_EQ(small.rgb.size(), 300u * 200u * 3u);
  EXPECT_EQ(small.at(0, 0), kBlack);
  EXPECT_EQ(small.at(150, 199), kWhite);
  EXPECT_EQ(small.at(150, 50), kLanderFill);  // Half of (300, 100).
  EXPECT_NEAR(FindColor(small, kLanderFill).count,
              FindColor(RenderAt(env, {.x = 10, .y = 10}), kLanderFill).count / 4.0, 80);
  // A tiny image still shows both flag poles.
  const Image tiny = RenderedSized(env, 60, 40);
  ASSERT_EQ(tiny.rgb.size(), 60u * 40u * 3u);
  EXPECT_EQ(tiny.at(24, 28), kWhite);
  EXPECT_EQ(tiny.at(36, 28), kWhite);
  std::vector<uint8_t> rgb;
  EXPECT_THROW(env.RenderSized(0, 10, &rgb), std::invalid_argument);
  EXPECT_THROW(env.RenderSized(10, -1, &rgb), std::invalid_argument);
}

// (Render before Reset and the native size of every id: specs_test.cc.)
TEST(LunarLanderRenderTest, RenderThroughTheRegistryDrawsTheLander) {
  auto env = MakeEnv("LunarLanderContinuous-v3");
  env->Reset(0);
  const Image image = Rendered(*env);
  // The lander starts at the top edge (y = H), so the upper part of its hull is cut off.
  EXPECT_GT(FindColor(image, kLanderFill).count, 200);
  EXPECT_EQ(image.at(300, 5), kLanderFill);
}

}  // namespace
}  // namespace rl::envs
