#include <cmath>
#include <numbers>
#include <stdexcept>
#include <vector>

#include <gtest/gtest.h>

#include "envs/pendulum.h"
#include "envs/raster.h"
#include "tests/envs/image_testing.h"
#include "tests/envs/render_checks.h"

namespace rl::envs {
namespace {

constexpr double kPi = std::numbers::pi;
constexpr Rgb kRod{204, 77, 77};
constexpr Rgb kArrow{64, 64, 64};
// 500 / 4.4 pixels per world unit; the axle is the reference's pixel (250, 250) before the
// vertical flip, so pixel (250, 249) of the image, centred on (250.5, 249.5).
constexpr double kScale = 500 / 4.4;
constexpr double kAxleX = 250.5;
constexpr double kAxleY = 249.5;

Image RenderState(double theta, double theta_dot = 0) {
  Pendulum env;
  env.SetState(theta, theta_dot);
  return Rendered(env);
}

// Renders after one step with torque u from (theta, 0).
Image RenderAfterTorque(double theta, float u) {
  Pendulum env;
  env.SetState(theta, 0);
  const float action[] = {u};
  env.Step(action);
  return Rendered(env);
}

TEST(PendulumRenderTest, ImageIs500By500RgbOnWhite) {
  const Image image = RenderState(0);
  ExpectSize(image, 500, 500);
  ExpectPixels(image, {{0, 0, kWhite}, {499, 499, kWhite}, {499, 0, kWhite}});
  // The rod and its caps cover about 0.2 x 1.2 world units of the 4.4 x 4.4 view.
  const Blob rod = FindColor(image, kRod);
  EXPECT_NEAR(rod.count, 0.2 * kScale * kScale + kPi * 11 * 11 - kPi * 5 * 5, 150);
  EXPECT_GT(FindColor(image, kWhite).count, 500 * 500 * 9 / 10);
  EXPECT_EQ(FindColor(image, kArrow).count, 0);  // No torque yet.
}

TEST(PendulumRenderTest, UprightRodPointsUpFromTheAxle) {
  const Image image = RenderState(0);
  // Half the rod's length is 57 pixels.
  EXPECT_EQ(image.at(250, 249 - 57), kRod);
  EXPECT_EQ(image.at(250, 249 - 100), kRod);
  EXPECT_EQ(image.at(240, 249 - 57), kRod);  // 0.1 world units (11 px) to either side.
  EXPECT_EQ(image.at(260, 249 - 57), kRod);
  EXPECT_EQ(image.at(237, 249 - 57), kWhite);
  EXPECT_EQ(image.at(263, 249 - 57), kWhite);
  EXPECT_EQ(image.at(250, 249 - 130), kWhite);  // Past the end cap (1 + 0.1 units).
  EXPECT_EQ(image.at(250, 249 + 57), kWhite);
  EXPECT_EQ(image.at(250 - 57, 249), kWhite);
  EXPECT_EQ(image.at(250 + 57, 249), kWhite);
  const Blob rod = FindColor(image, kRod);
  EXPECT_NEAR(rod.mean_x, 250, 1.0);
  EXPECT_LT(rod.mean_y, 249 - 50);
}

TEST(PendulumRenderTest, RodTurnsCounterClockwiseWithTheta) {
  // A quarter turn points the rod left, minus a quarter turn right, half a turn down.
  const Image left = RenderState(kPi / 2);
  EXPECT_EQ(left.at(250 - 57, 249), kRod);
  EXPECT_EQ(left.at(250 + 57, 249), kWhite);
  EXPECT_EQ(left.at(250, 249 - 57), kWhite);
  const Image right = RenderState(-kPi / 2);
  EXPECT_EQ(right.at(250 + 57, 249), kRod);
  EXPECT_EQ(right.at(250 - 57, 249), kWhite);
  const Image down = RenderState(kPi);
  EXPECT_EQ(down.at(250, 249 + 57), kRod);
  EXPECT_EQ(down.at(250, 249 - 57), kWhite);
  // At any angle the rod's pixels centre on half its length along (cos, sin)(theta + pi/2), y up.
  // The axle hides the rod's root, which moves the mean outwards by about 2 px.
  for (const double theta : {0.0, 0.7, 2.5, -1.2, 10.0, -20.0}) {
    SCOPED_TRACE(theta);
    const Blob rod = FindColor(RenderState(theta), kRod);
    const double a = theta + kPi / 2;
    EXPECT_NEAR(rod.mean_x, kAxleX - 0.5 + 0.5 * kScale * std::cos(a), 3.0);
    EXPECT_NEAR(rod.mean_y, kAxleY - 0.5 - 0.5 * kScale * std::sin(a), 3.0);
  }
}

TEST(PendulumRenderTest, AxleIsABlackDiscAtTheCentre) {
  const Image image = RenderState(0);
  EXPECT_EQ(image.at(250, 249), kBlack);
  EXPECT_EQ(image.at(255, 249), kBlack);  // Radius int(0.05 * 113.6) = 5 px.
  EXPECT_EQ(image.at(245, 249), kBlack);
  EXPECT_EQ(image.at(250, 254), kBlack);
  EXPECT_EQ(image.at(250, 244), kBlack);
  EXPECT_EQ(image.at(250, 255), kRod);  // Then the rod's round cap (11 px) around it.
  EXPECT_EQ(image.at(250, 260), kRod);
  EXPECT_EQ(image.at(250, 262), kWhite);
  const Blob axle = FindColor(image, kBlack);
  EXPECT_NEAR(axle.count, kPi * 5 * 5, 8);
  EXPECT_NEAR(axle.mean_x, 250, 0.01);
  EXPECT_NEAR(axle.mean_y, 249, 0.01);
  // The axle stays on top whatever the angle and torque.
  EXPECT_EQ(RenderAfterTorque(1.0, 0.1f).at(250, 249), kBlack);
}

TEST(PendulumRenderTest, TorqueArrowTurnsWithTheSignOfTheTorque) {
  // Hanging down, so that the rod does not cover the upper half. The arrow is a ring of radius
  // 0.28 to 0.38 of its 113.6 px square (32 to 43 px) with a gap at the top, and its head at the
  // upper right for u > 0 (counter-clockwise), at the upper left for u < 0 (clockwise).
  const Image ccw = RenderAfterTorque(kPi, 2.0f);
  const Image cw = RenderAfterTorque(kPi, -2.0f);
  for (const Image* image : {&ccw, &cw}) {
    EXPECT_EQ(image->at(250 - 37, 249), kArrow);  // Left.
    EXPECT_EQ(image->at(250 + 37, 249), kArrow);  // Right.
    EXPECT_EQ(image->at(250, 249 + 37), kArrow);  // Below, over the rod.
    EXPECT_EQ(image->at(250, 249 - 37), kWhite);  // The gap at the top.
    EXPECT_EQ(image->at(250 - 60, 249), kWhite);  // Outside the square.
  }
  // The heads: a triangle entering the gap from the side the arrow comes from.
  EXPECT_EQ(ccw.at(271, 217), kArrow);
  EXPECT_EQ(ccw.at(229, 217), kWhite);
  EXPECT_EQ(cw.at(229, 217), kArrow);
  EXPECT_EQ(cw.at(271, 217), kWhite);
  // One is the other's mirror image about the axle's column.
  const Blob a = FindColor(ccw, kArrow);
  const Blob b = FindColor(cw, kArrow);
  EXPECT_NEAR(a.count, b.count, 0.02 * a.count);
  EXPECT_GT(a.mean_x, 252);
  EXPECT_LT(b.mean_x, 248);
  EXPECT_NEAR(a.mean_x + b.mean_x, 500, 1.0);
  EXPECT_NEAR(a.mean_y, b.mean_y, 0.5);
}

TEST(PendulumRenderTest, TorqueArrowScalesWithTheClippedTorque) {
  const Blob full = FindColor(RenderAfterTorque(kPi, 2.0f), kArrow);
  const Blob half = FindColor(RenderAfterTorque(kPi, 1.0f), kArrow);
  ASSERT_GT(full.count, 0);
  // The area goes with the square of |u|.
  EXPECT_NEAR(static_cast<double>(half.count) / full.count, 0.25, 0.04);
  // Half the torque: the ring at 16 to 21 px, nothing at 37 px.
  const Image small = RenderAfterTorque(kPi, 1.0f);
  EXPECT_EQ(small.at(250 - 19, 249), kArrow);
  EXPECT_EQ(small.at(250 - 37, 249), kWhite);
  // A torque beyond the bounds draws what the bound draws; none draws nothing.
  EXPECT_EQ(RenderAfterTorque(kPi, 9.0f).rgb, RenderAfterTorque(kPi, 2.0f).rgb);
  EXPECT_EQ(FindColor(RenderAfterTorque(kPi, 0.0f), kArrow).count, 0);
  // A Reset forgets the torque.
  Pendulum env;
  env.Reset(4);
  const float action[] = {2.0f};
  env.Step(action);
  EXPECT_GT(FindColor(Rendered(env), kArrow).count, 0);
  env.Reset(4);
  EXPECT_EQ(FindColor(Rendered(env), kArrow).count, 0);
}

TEST(PendulumRenderTest, RenderSizedDrawsAtTheRequestedSize) {
  Pendulum env;
  env.SetState(0, 0);
  // At the native size it is Render's image.
  const Image native = Rendered(env);
  std::vector<uint8_t> same;
  env.RenderSized(500, 500, &same);
  EXPECT_EQ(same, native.rgb);
  // 250 x 100: each axis scaled on its own; the upright rod is above the axle at (125, 50).
  Image small{.rgb = {}, .width = 250, .height = 100};
  env.RenderSized(small.width, small.height, &small.rgb);
  ASSERT_EQ(small.rgb.size(), 250U * 100U * 3U);
  EXPECT_EQ(small.at(125, 38), kRod);
  EXPECT_EQ(small.at(125, 61), kWhite);
  EXPECT_EQ(small.at(0, 0), kWhite);
  const Blob rod = FindColor(small, kRod);
  const Blob native_rod = FindColor(native, kRod);
  EXPECT_NEAR(rod.mean_x, (native_rod.mean_x + 0.5) * 0.5 - 0.5, 1.0);
  EXPECT_NEAR(rod.mean_y, (native_rod.mean_y + 0.5) * 0.2 - 0.5, 1.0);
  env.SetState(kPi / 2, 0);  // Left.
  env.RenderSized(small.width, small.height, &small.rgb);
  EXPECT_EQ(small.at(96, 49), kRod);
  EXPECT_EQ(small.at(154, 49), kWhite);
  // An 84 x 84 frame, as a pixel pipeline would ask for.
  std::vector<uint8_t> frame;
  env.RenderSized(84, 84, &frame);
  EXPECT_EQ(frame.size(), 84U * 84U * 3U);
}

TEST(PendulumRenderTest, RefusesBadSizesAndRenderingBeforeReset) {
  Pendulum env;
  ExpectRenderRefusedBeforeReset(env);
  env.Reset(2);
  std::vector<uint8_t> rgb;
  EXPECT_THROW(env.RenderSized(0, 10, &rgb), std::invalid_argument);
  EXPECT_THROW(env.RenderSized(10, -1, &rgb), std::invalid_argument);
  EXPECT_NO_THROW(Rendered(env));
}

}  // namespace
}  // namespace rl::envs
