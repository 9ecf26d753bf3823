#include "envs/raster.h"

#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <numbers>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

namespace rl::envs {
namespace {

constexpr Rgb kRed{255, 0, 0};

// A canvas of width x height, cleared to white, that owns the buffer it draws into (the buffer
// is a base, so that it is built before the Canvas that points to it).
struct CanvasBuffer {
  std::vector<uint8_t> buffer;
};
class WhiteCanvas : private CanvasBuffer, public Canvas {
 public:
  WhiteCanvas(int width, int height) : Canvas(width, height, &buffer) { Clear(kWhite); }
  WhiteCanvas(const WhiteCanvas&) = delete;
  WhiteCanvas& operator=(const WhiteCanvas&) = delete;
};

int CountColor(const Canvas& canvas, Rgb color) {
  int count = 0;
  for (int y = 0; y < canvas.height(); ++y) {
    for (int x = 0; x < canvas.width(); ++x) count += canvas.pixel(x, y) == color;
  }
  return count;
}

TEST(RasterTest, ClearPaintsEveryPixel) {
  std::vector<uint8_t> buffer;
  Canvas canvas(7, 5, &buffer);
  EXPECT_EQ(buffer.size(), 7u * 5u * 3u);
  canvas.Clear(Rgb{1, 2, 3});
  EXPECT_EQ(CountColor(canvas, Rgb{1, 2, 3}), 35);
  EXPECT_EQ(buffer[0], 1);
  EXPECT_EQ(buffer[1], 2);
  EXPECT_EQ(buffer[2], 3);
}

TEST(RasterTest, RectangleWithIntegerCornersCoversExactlyItsPixels) {
  WhiteCanvas canvas(20, 10);
  const std::array<Point, 4> rect = {Point{3, 2}, Point{3, 7}, Point{11, 7}, Point{11, 2}};
  canvas.FillPolygon(rect, kRed);
  EXPECT_EQ(CountColor(canvas, kRed), 8 * 5);
  EXPECT_EQ(canvas.pixel(3, 2), kRed);
  EXPECT_EQ(canvas.pixel(10, 6), kRed);
  EXPECT_EQ(canvas.pixel(11, 6), kWhite);
  EXPECT_EQ(canvas.pixel(10, 7), kWhite);
  EXPECT_EQ(canvas.pixel(2, 2), kWhite);
}

TEST(RasterTest, TrianglesSharingAnEdgeNeitherOverlapNorLeaveGaps) {
  // Two triangles splitting a square along a diagonal through pixel centres.
  const std::array<Point, 3> lower = {Point{2.5, 2.5}, Point{30.5, 2.5}, Point{30.5, 30.5}};
  const std::array<Point, 3> upper = {Point{2.5, 2.5}, Point{30.5, 30.5}, Point{2.5, 30.5}};
  WhiteCanvas a(40, 40), b(40, 40), both(40, 40);
  a.FillPolygon(lower, kRed);
  b.FillPolygon(upper, kRed);
  const std::array<Point, 4> square = {Point{2.5, 2.5}, Point{30.5, 2.5}, Point{30.5, 30.5},
                                       Point{2.5, 30.5}};
  both.FillPolygon(square, kRed);
  int overlap = 0;
  int mismatch = 0;
  for (int y = 0; y < 40; ++y) {
    for (int x = 0; x < 40; ++x) {
      const bool in_a = a.pixel(x, y) == kRed;
      const bool in_b = b.pixel(x, y) == kRed;
      overlap += in_a && in_b;
      mismatch += (in_a || in_b) != (both.pixel(x, y) == kRed);
    }
  }
  EXPECT_EQ(overlap, 0);
  EXPECT_EQ(mismatch, 0);
  EXPECT_EQ(CountColor(both, kRed), 28 * 28);
}

TEST(RasterTest, TriangleFanTilesItsPolygonExactlyOnce) {
  // A convex polygon with irregular vertices, split into a fan around an interior point; the
  // triangles alternate winding. Every pixel of the polygon is painted by exactly one triangle.
  const std::vector<Point> ring = {{10.3, 4.7},  {33.1, 2.2},  {47.9, 15.5}, {45.2, 38.6},
                                   {27.7, 47.1}, {6.05, 36.3}, {1.9, 17.5}};
  const Point centre{24.6, 23.5};  // Some vertices lie on pixel-centre rows.
  WhiteCanvas all(50, 50);
  all.FillPolygon(ring, kRed);
  std::vector<int> hits(50 * 50, 0);
  for (std::size_t i = 0; i < ring.size(); ++i) {
    std::array<Point, 3> triangle = {centre, ring[i], ring[(i + 1) % ring.size()]};
    if (i % 2 == 1) std::swap(triangle[1], triangle[2]);
    WhiteCanvas canvas(50, 50);
    canvas.FillPolygon(triangle, kRed);
    for (int y = 0; y < 50; ++y) {
      for (int x = 0; x < 50; ++x) hits[y * 50 + x] += canvas.pixel(x, y) == kRed;
    }
  }
  for (int y = 0; y < 50; ++y) {
    for (int x = 0; x < 50; ++x) {
      ASSERT_EQ(hits[y * 50 + x], all.pixel(x, y) == kRed ? 1 : 0) << "pixel " << x << ", " << y;
    }
  }
  EXPECT_GT(CountColor(all, kRed), 1200);
}

TEST(RasterTest, RotatedSquareCoversAboutItsArea) {
  WhiteCanvas canvas(100, 100);
  // A 40x40 square rotated by 30 degrees about (50, 50).
  std::array<Point, 4> square;
  const double c = std::cos(std::numbers::pi / 6), s = std::sin(std::numbers::pi / 6);
  const std::array<std::array<double, 2>, 4> corners = {
      {{-20, -20}, {20, -20}, {20, 20}, {-20, 20}}};
  for (int i = 0; i < 4; ++i) {
    square[i] = Point{50 + corners[i][0] * c - corners[i][1] * s,
                      50 + corners[i][0] * s + corners[i][1] * c};
  }
  canvas.FillPolygon(square, kRed);
  EXPECT_NEAR(CountColor(canvas, kRed), 1600, 40);
}

TEST(RasterTest, CircleCoversAboutPiRSquaredSymmetrically) {
  WhiteCanvas canvas(64, 64);
  canvas.FillEllipse(Point{32, 32}, 20, 20, kRed);
  EXPECT_NEAR(CountColor(canvas, kRed), std::numbers::pi * 400, 40);
  for (int d = 0; d < 25; ++d) {
    EXPECT_EQ(canvas.pixel(32 + d, 32) == kRed, canvas.pixel(31 - d, 32) == kRed) << d;
    EXPECT_EQ(canvas.pixel(32, 32 + d) == kRed, canvas.pixel(32, 31 - d) == kRed) << d;
  }
  EXPECT_EQ(canvas.pixel(51, 32), kRed);
  EXPECT_EQ(canvas.pixel(52, 32), kWhite);
}

TEST(RasterTest, EllipseUsesBothRadii) {
  WhiteCanvas canvas(64, 64);
  canvas.FillEllipse(Point{32, 32}, 20, 5, kRed);
  EXPECT_NEAR(CountColor(canvas, kRed), std::numbers::pi * 100, 25);
  EXPECT_EQ(canvas.pixel(50, 32), kRed);
  EXPECT_EQ(canvas.pixel(32, 40), kWhite);
}

TEST(RasterTest, ShapesAreClippedToTheImage) {
  WhiteCanvas canvas(10, 10);
  const std::array<Point, 4> big = {Point{-5, -5}, Point{15, -5}, Point{15, 15}, Point{-5, 15}};
  canvas.FillPolygon(big, kRed);
  EXPECT_EQ(CountColor(canvas, kRed), 100);

  canvas.Clear(kWhite);
  canvas.FillEllipse(Point{0, 0}, 3, 3, kRed);
  EXPECT_GT(CountColor(canvas, kRed), 0);
  EXPECT_LT(CountColor(canvas, kRed), 12);
  canvas.FillPixelRect(-3, 8, 50, 50, kRed);
  EXPECT_EQ(canvas.pixel(9, 9), kRed);
}

TEST(RasterTest, HugeOrNonFiniteCoordinatesDrawNothingOrClipSafely) {
  WhiteCanvas canvas(10, 10);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  const std::array<Point, 3> with_nan = {Point{0, 0}, Point{nan, 5}, Point{5, 5}};
  const std::array<Point, 3> with_inf = {Point{0, 0}, Point{inf, 5}, Point{5, 5}};
  const std::array<Point, 3> far = {Point{1e300, 1e300}, Point{2e300, 1e300}, Point{1e300, 2e300}};
  canvas.FillPolygon(with_nan, kRed);
  canvas.FillPolygon(with_inf, kRed);
  canvas.FillPolygon(far, kRed);
  canvas.FillEllipse(Point{nan, 0}, 3, 3, kRed);
  canvas.FillEllipse(Point{1e300, -1e300}, 1e300, 1e300, kRed);
  canvas.FillEllipse(Point{5, 5}, 0, 3, kRed);
  const std::array<Point, 2> line = {Point{0, 0}, Point{9, 9}};
  canvas.FillPolygon(line, kRed);
  EXPECT_EQ(CountColor(canvas, kRed), 0);
  // A huge polygon covering the image is clipped, not overflowed.
  const std::array<Point, 3> huge = {Point{-1e300, -1e300}, Point{1e300, -1e300}, Point{0, 1e300}};
  canvas.FillPolygon(huge, kRed);
  EXPECT_EQ(CountColor(canvas, kRed), 100);
}

TEST(RasterTest, ResizeAreaAveragesWhenShrinkingAndCopiesAtTheSameSize) {
  // A 2x2 image: black, white / white, white.
  const std::vector<uint8_t> src = {0, 0, 0, 255, 255, 255, 255, 255, 255, 255, 255, 255};
  std::vector<uint8_t> dst;
  ResizeRgbArea(src, 2, 2, 2, 2, &dst);
  EXPECT_EQ(dst, src);
  ResizeRgbArea(src, 2, 2, 1, 1, &dst);
  EXPECT_EQ(dst, (std::vector<uint8_t>{191, 191, 191}));  // round(3 * 255 / 4)
  ResizeRgbArea(src, 2, 2, 4, 1, &dst);
  ASSERT_EQ(dst.size(), 12u);
  EXPECT_EQ(dst[0], 128);  // Left column: one black, one white.
  EXPECT_EQ(dst[9], 255);
  // Shrinking by a non-integer factor keeps a constant image constant.
  const std::vector<uint8_t> grey(5 * 3 * 3, 77);
  ResizeRgbArea(grey, 5, 3, 2, 2, &dst);
  EXPECT_EQ(dst, std::vector<uint8_t>(2 * 2 * 3, 77));
}

}  // namespace
}  // namespace rl::envs
