#include "evaluator/raster_canvas.h"

#include <algorithm>
#include <stdexcept>

#include <gtest/gtest.h>

#include "evaluator/plot.h"

namespace rl::evaluator {
namespace {

using plot::Colour;
using plot::Paint;

// The pixel at (x, y) as a colour.
Colour At(RasterCanvas& canvas, int x, int y) {
  const cv::Vec3b bgr = canvas.image().at<cv::Vec3b>(y, x);
  return {bgr[2], bgr[1], bgr[0]};
}

const Colour kRed = Colour::Hex(0xff0000);
const Colour kWhite = Colour::Hex(0xffffff);

TEST(RasterCanvasTest, DrawsShapesInTheirColoursOnWhite) {
  RasterCanvas canvas(60, 40);
  EXPECT_EQ(canvas.width(), 60);
  EXPECT_EQ(canvas.height(), 40);
  EXPECT_EQ(At(canvas, 0, 0), kWhite);
  canvas.Circle({10, 10}, 4, Paint::Fill(kRed));
  EXPECT_EQ(At(canvas, 10, 10), kRed);
  EXPECT_EQ(At(canvas, 10, 16), kWhite);
  Paint crisp = Paint::Stroke(Colour::Hex(0x0000ff));
  crisp.crisp = true;
  canvas.Line({20, 30}, {50, 30}, crisp);
  EXPECT_EQ(At(canvas, 35, 30), Colour::Hex(0x0000ff));
  EXPECT_EQ(At(canvas, 35, 31), kWhite);
  canvas.Rect({30, 2}, 10, 10, Paint::Fill(Colour::Hex(0x00ff00)));
  EXPECT_EQ(At(canvas, 35, 7), Colour::Hex(0x00ff00));
}

TEST(RasterCanvasTest, BlendsTranslucentFillsAndLeavesGapsInDashes) {
  RasterCanvas canvas(40, 20);
  canvas.Rect({0, 0}, 10, 10, Paint::Fill(Colour::Hex(0x000000), 0.5));
  const Colour half = At(canvas, 5, 5);
  EXPECT_NEAR(half.r, 128, 1);
  Paint dashed = Paint::Stroke(kRed);
  dashed.crisp = true;
  dashed.dash = {4, 4};
  canvas.Line({12, 15}, {36, 15}, dashed);
  EXPECT_EQ(At(canvas, 13, 15), kRed);    // in the first dash
  EXPECT_EQ(At(canvas, 18, 15), kWhite);  // in the first gap
  EXPECT_EQ(At(canvas, 21, 15), kRed);    // in the second dash
}

TEST(RasterCanvasTest, AnchorsTextAndRefusesRotatedText) {
  RasterCanvas canvas(200, 40);
  plot::Font font;
  font.size = 15;
  font.colour = Colour::Hex(0x000000);
  font.anchor = plot::Anchor::kEnd;
  const double width = canvas.TextWidth("evaluator", font.size);
  EXPECT_GT(width, 40);
  canvas.Text({190, 30}, "evaluator", font);
  // Ink only left of the anchor, within the text's width.
  int ink_left = 200, ink_right = -1;
  for (int x = 0; x < 200; ++x) {
    for (int y = 0; y < 40; ++y) {
      if (At(canvas, x, y).r < 128) {
        ink_left = std::min(ink_left, x);
        ink_right = std::max(ink_right, x);
      }
    }
  }
  EXPECT_LE(ink_right, 191);
  EXPECT_GE(ink_left, 190 - width - 2);
  font.rotation = -90;
  EXPECT_THROW(canvas.Text({10, 10}, "up", font), std::invalid_argument);
}

TEST(RasterCanvasTest, DrawsAColourBarOfThePlotModuleRowByRow) {
  RasterCanvas canvas(100, 140);
  plot::Font font;
  font.size = 13.5;
  font.colour = Colour::Hex(0x282828);
  const Colour low = Colour::Hex(0x440154), high = Colour::Hex(0xfde725);
  plot::DrawColourBar(&canvas, plot::ColourScale(0, 1, {low, high}), {20, 20}, 16, 100, "v", font);
  EXPECT_EQ(At(canvas, 28, 22), high);         // high values at the top
  EXPECT_EQ(At(canvas, 28, 117), low);         // low ones at the bottom
  EXPECT_EQ(At(canvas, 20, 60), font.colour);  // the outline
  EXPECT_EQ(At(canvas, 95, 60), kWhite);       // right of the tick labels
}

}  // namespace
}  // namespace rl::evaluator
