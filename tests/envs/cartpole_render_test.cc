#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <vector>

#include <gtest/gtest.h>

#include "envs/cartpole.h"
#include "envs/raster.h"
#include "envs/registry.h"
#include "tests/envs/image_testing.h"
#include "tests/envs/render_checks.h"

namespace rl::envs {
namespace {

constexpr Rgb kPole{202, 152, 101};
constexpr Rgb kAxle{129, 132, 203};

Image RenderState(const std::array<double, 4>& state) {
  CartPole env;
  env.set_state(state);
  return Rendered(env);
}

// In the 600x400 image (y down) the track is row 400 - 1 - 100 = 299; the cart is centred on
// column x * 125 + 300 and spans rows [400 - 115, 400 - 85) = [285, 315).
constexpr int kTrackRow = 299;

TEST(CartPoleRenderTest, ImageIs600By400RgbOnWhite) {
  const Image image = RenderState({0, 0, 0, 0});
  ExpectSize(image, 600, 400);
  ExpectPixels(image, {{0, 0, kWhite}, {599, 399, kWhite}, {100, 150, kWhite}});
  // Mostly background.
  EXPECT_GT(FindColor(image, kWhite).count, 600 * 400 * 9 / 10);
}

TEST(CartPoleRenderTest, TrackIsABlackRowAcrossTheWholeWidth) {
  const Image image = RenderState({0, 0, 0, 0});
  for (int x = 0; x < 600; ++x) ASSERT_EQ(image.at(x, kTrackRow), kBlack) << "column " << x;
  EXPECT_EQ(image.at(10, kTrackRow - 1), kWhite);
  EXPECT_EQ(image.at(10, kTrackRow + 1), kWhite);
}

TEST(CartPoleRenderTest, CartIsABlack50By30RectangleAtTheCentre) {
  const Image image = RenderState({0, 0, 0, 0});
  // Corners of the cart, below the axle and pole, and a pixel inside.
  ExpectPixels(image, {{275, 285, kBlack},
                       {324, 285, kBlack},
                       {275, 314, kBlack},
                       {324, 314, kBlack},
                       {280, 310, kBlack}});
  // Just outside.
  ExpectPixels(image,
               {{274, 310, kWhite}, {325, 310, kWhite}, {280, 284, kWhite}, {280, 315, kWhite}});
  // The black pixels off the track row are the cart minus what the pole and axle cover.
  const Blob cart = FindColor(image, kBlack, kTrackRow);
  EXPECT_GT(cart.count, 50 * 29 - 150);
  EXPECT_LE(cart.count, 50 * 29);
  EXPECT_NEAR(cart.mean_x, 299.5, 0.5);
}

TEST(CartPoleRenderTest, UprightPoleAndAxleSitAboveTheCart) {
  const Image image = RenderState({0, 0, 0, 0});
  // The pole runs from 2.5 px below the axle to 122.5 px above it: rows (172.5, 297.5).
  ExpectPixels(image,
               {{300, 200, kPole}, {296, 180, kPole}, {300, 170, kWhite}, {290, 200, kWhite}});
  const Blob pole = FindColor(image, kPole);
  EXPECT_NEAR(pole.mean_x, 299.5, 0.5);
  EXPECT_NEAR(pole.count, 10 * 125 - 80, 60);  // Minus what the axle covers.
  // Axle: radius-5 disc centred on pixel (300, 292).
  ExpectPixels(image, {{300, 292, kAxle}, {305, 292, kAxle}, {300, 287, kAxle}});
  const Blob axle = FindColor(image, kAxle);
  EXPECT_NEAR(axle.count, 3.14159 * 25, 12);
  EXPECT_NEAR(axle.mean_x, 300, 0.01);
  EXPECT_NEAR(axle.mean_y, 292, 0.01);
}

TEST(CartPoleRenderTest, MovingTheCartMovesTheBlackPixels) {
  const Image centre = RenderState({0, 0, 0, 0});
  const Image right = RenderState({1.0, 0, 0, 0});  // 125 px to the right.
  EXPECT_EQ(right.at(280, 310), kWhite);
  EXPECT_EQ(right.at(405, 310), kBlack);
  const Blob a = FindColor(centre, kBlack, kTrackRow);
  const Blob b = FindColor(right, kBlack, kTrackRow);
  EXPECT_EQ(a.count, b.count);
  EXPECT_DOUBLE_EQ(b.mean_x - a.mean_x, 125.0);
  EXPECT_DOUBLE_EQ(b.mean_y, a.mean_y);

  const Image left = RenderState({-1.2, 0, 0, 0});  // 150 px to the left.
  EXPECT_DOUBLE_EQ(FindColor(left, kBlack, kTrackRow).mean_x - a.mean_x, -150.0);
}

TEST(CartPoleRenderTest, PositiveThetaLeansThePoleTowardsPositiveX) {
  const Image upright = RenderState({0, 0, 0, 0});
  const Image leaning = RenderState({0, 0, 0.2, 0});
  const Blob a = FindColor(upright, kPole);
  const Blob b = FindColor(leaning, kPole);
  // The pole's centre is about 57.5 px from the axle along its axis.
  EXPECT_NEAR(b.mean_x - a.mean_x, 57.5 * std::sin(0.2), 3.0);
  EXPECT_GT(b.mean_y, a.mean_y);  // Lower in the image: the pole tilts down.
  // The far end is at about 120 px from the axle.
  EXPECT_EQ(leaning.at(300 + static_cast<int>(115 * std::sin(0.2)),
                       292 - static_cast<int>(115 * std::cos(0.2))),
            kPole);
}

TEST(CartPoleRenderTest, RenderSizedScalesTheSamePicture) {
  CartPole env;
  env.set_state({0.8, 0, 0, 0});  // Cart centre at column 400 of 600.
  const Image small = RenderedSized(env, 300, 200);
  ASSERT_EQ(small.rgb.size(), 300u * 200u * 3u);
  EXPECT_EQ(small.at(0, 0), kWhite);
  EXPECT_EQ(small.at(200, 155), kBlack);  // Cart at half scale: centre (200, 150).
  EXPECT_EQ(small.at(150, 155), kWhite);
  EXPECT_GT(FindColor(small, kPole).count, 200);
  EXPECT_GT(FindColor(small, kAxle).count, 10);
  // The track stays at least one pixel thick when shrinking a lot.
  const Image tiny = RenderedSized(env, 60, 40);
  ASSERT_EQ(tiny.rgb.size(), 60u * 40u * 3u);
  int black_rows = 0;
  for (int y = 0; y < 40; ++y) black_rows += tiny.at(1, y) == kBlack;
  EXPECT_EQ(black_rows, 1);
  std::vector<uint8_t> rgb;
  EXPECT_THROW(env.RenderSized(0, 10, &rgb), std::invalid_argument);
}

TEST(CartPoleRenderTest, RunawayStatesRenderWithoutCrashing) {
  for (double x : {50.0, -1e300, 1e300}) {
    const Image image = RenderState({x, 0, 3.0, 0});
    EXPECT_EQ(image.rgb.size(), 600u * 400u * 3u);
    EXPECT_EQ(image.at(300, 310), kWhite);  // The cart is off screen.
    EXPECT_EQ(image.at(300, kTrackRow), kBlack);
  }
}

// (Render before Reset and the native size of every id: specs_test.cc.)
TEST(CartPoleRenderTest, RenderThroughTheRegistryDrawsThePole) {
  auto env = MakeEnv("CartPole-v1");
  env->Reset(0);
  const Image image = Rendered(*env);
  EXPECT_GT(FindColor(image, kPole).count, 1000);
}

}  // namespace
}  // namespace rl::envs
