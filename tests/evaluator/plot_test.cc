#include "evaluator/plot.h"

#include <algorithm>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "evaluator/svg_canvas.h"

namespace rl::plot {
namespace {

TEST(NiceTicksTest, CoverTheRangeWithRoundSteps) {
  const std::vector<double> t = NiceTicks(0, 475, 5);
  ASSERT_GE(t.size(), 2U);
  EXPECT_LE(t.front(), 0);
  EXPECT_GE(t.back(), 475);
  EXPECT_EQ(t, (std::vector<double>{0, 100, 200, 300, 400, 500}));
  const std::vector<double> big = NiceTicks(0, 1.3e6, 6);
  EXPECT_EQ(big.back(), 1.4e6);
  EXPECT_DOUBLE_EQ(big[1] - big[0], 2e5);
}

TEST(NiceTicksTest, AnEmptyRangeIsWidened) {
  const std::vector<double> t = NiceTicks(10, 10, 5);
  ASSERT_GE(t.size(), 2U);
  EXPECT_LT(t.front(), t.back());
  EXPECT_LE(t.front(), 10);
  EXPECT_GE(t.back(), 10);
}

TEST(FormatTickTest, WritesPlainNumbersAndCounts) {
  EXPECT_EQ(FormatTick(500, TickFormat::kPlain), "500");
  EXPECT_EQ(FormatTick(0.25, TickFormat::kPlain), "0.25");
  EXPECT_EQ(FormatTick(-1e-12, TickFormat::kPlain), "0");
  EXPECT_EQ(FormatTick(800, TickFormat::kCount), "800");
  EXPECT_EQ(FormatTick(1500, TickFormat::kCount), "1.5k");
  EXPECT_EQ(FormatTick(50000, TickFormat::kCount), "50k");
  EXPECT_EQ(FormatTick(1.5e6, TickFormat::kCount), "1.5M");
  EXPECT_EQ(FormatTick(2e9, TickFormat::kCount), "2G");
  EXPECT_EQ(PickTimeUnit(119).name, "s");
  EXPECT_EQ(PickTimeUnit(120).seconds, 60);
  EXPECT_EQ(PickTimeUnit(7200).name, "h");
}

// The numbers of the attribute `name` of every `tag` element, in order.
std::vector<double> Attributes(const std::string& svg, const std::string& tag,
                               const std::string& name) {
  std::vector<double> values;
  for (size_t at = svg.find("<" + tag + " "); at != std::string::npos;
       at = svg.find("<" + tag + " ", at + 1)) {
    const size_t end = svg.find('>', at);
    const size_t attr = svg.find(" " + name + "=\"", at);
    if (attr == std::string::npos || attr > end) continue;
    values.push_back(std::stod(svg.substr(attr + name.size() + 3)));
  }
  return values;
}

TEST(SvgCanvasTest, WritesShapesWithTheirPaintClassesAndEscapedTooltips) {
  SvgCanvas canvas(200, 100, "a <title>", kTextColour);
  Paint dashed = Paint::Stroke(kGoalColour, 1.5);
  dashed.dash = {6, 4};
  canvas.Line({0, 50}, {200, 50}, dashed, {"goal", ""});
  const Point steps[] = {{10, 90}, {50, 90}, {50, 40}, {90, 40}, {120, 10}};
  canvas.Path(steps, true, Paint::Fill(kLineColour, 0.25), {"band", "min & max"});
  canvas.Circle({5, 6}, 2.5, Paint::Fill(kLineColour));
  Font font;
  font.colour = kAxisColour;
  font.anchor = Anchor::kEnd;
  font.rotation = -90;
  canvas.Text({18, 50}, "x < y", font);
  const std::string svg = canvas.Document();
  EXPECT_EQ(svg.rfind("<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"200\" height=\"100\"", 0),
            0U);
  EXPECT_NE(svg.find("<title>a &lt;title&gt;</title>"), std::string::npos);
  EXPECT_NE(svg.find("<line class=\"goal\" x1=\"0.0\" y1=\"50.0\" x2=\"200.0\" y2=\"50.0\" "
                     "fill=\"none\" stroke=\"#d1242f\" stroke-width=\"1.5\" "
                     "stroke-dasharray=\"6 4\"/>"),
            std::string::npos)
      << svg;
  // Level and upright segments as H and V; a tooltip as a <title> child.
  EXPECT_NE(svg.find("<path class=\"band\" d=\"M10.0,90.0 H50.0 V40.0 H90.0 L120.0,10.0 Z\" "
                     "fill=\"#1f6feb\" fill-opacity=\"0.25\"><title>min &amp; max</title></path>"),
            std::string::npos)
      << svg;
  EXPECT_NE(svg.find("<circle cx=\"5.0\" cy=\"6.0\" r=\"2.5\" fill=\"#1f6feb\"/>"),
            std::string::npos);
  EXPECT_NE(svg.find("fill=\"#57606a\" text-anchor=\"end\" transform=\"rotate(-90 18.0 50.0)\">"
                     "x &lt; y</text>"),
            std::string::npos)
      << svg;
  EXPECT_EQ(svg.substr(svg.size() - 7), "</svg>\n");
  EXPECT_DOUBLE_EQ(canvas.TextWidth("ab\xC2\xB1", 10), 3 * 5.4);  // code points, not bytes
}

TEST(ChartTest, MapsDataIntoThePlotAreaAndDrawsItsFrame) {
  ChartSpec spec;
  spec.width = 400;
  spec.height = 300;
  spec.title = "Return";
  spec.x_label = "wall time";
  spec.y_label = "return";
  spec.x_min = 0;
  spec.x_max = 600;  // seconds, labelled in minutes
  spec.x_unit = 60;
  spec.y_min = -10;
  spec.y_max = 475;
  const Chart chart(spec);
  // The axes cover the data with round ticks: 0 to 10 minutes, -100 to 500.
  EXPECT_DOUBLE_EQ(chart.At(0, 0).x, Chart::kLeft);
  EXPECT_DOUBLE_EQ(chart.At(600, 0).x, 400 - Chart::kRight);
  EXPECT_DOUBLE_EQ(chart.At(0, 500).y, Chart::kTop);
  EXPECT_DOUBLE_EQ(chart.At(0, -100).y, 300 - Chart::kBottom);
  EXPECT_LT(chart.At(0, 10).y, chart.At(0, 0).y);  // y up
  SvgCanvas canvas(400, 300, spec.title, kTextColour);
  chart.DrawFrame(&canvas);
  const std::string svg = canvas.Document();
  for (const char* label : {">Return<", ">wall time<", ">return<", ">10<", ">500<", ">-100<"}) {
    EXPECT_NE(svg.find(label), std::string::npos) << label;
  }
  // Grid lines at every tick: x at 0, 2, ..., 10 minutes, y at -100, 0, ..., 500.
  EXPECT_EQ(Attributes(svg, "line", "x1").size(), 6U + 7U);
}

TEST(StepTest, CornersHoldEachValueUntilTheNextPointAndTheBandReturnsBelow) {
  const Point up[] = {{0, 1}, {2, 3}, {5, 4}};
  const Point down[] = {{0, 0}, {2, 1}, {5, 2}};
  const std::vector<Point> corners = StepCorners(up);
  const std::vector<Point> want = {{0, 1}, {2, 1}, {2, 3}, {5, 3}, {5, 4}};
  ASSERT_EQ(corners.size(), want.size());
  for (size_t i = 0; i < want.size(); ++i) {
    EXPECT_EQ(corners[i].x, want[i].x) << i;
    EXPECT_EQ(corners[i].y, want[i].y) << i;
  }
  const std::vector<Point> band = StepBand(up, down);
  ASSERT_EQ(band.size(), 10U);
  EXPECT_EQ(band[5].x, 5);  // back along the lower edge from its end
  EXPECT_EQ(band[5].y, 2);
  EXPECT_EQ(band[6].y, 1);
  EXPECT_EQ(band[9].x, 0);
  EXPECT_EQ(band[9].y, 0);
  EXPECT_TRUE(StepCorners({}).empty());
}

TEST(EndLabelsTest, LabelsOfPointsCloseTogetherDoNotOverlap) {
  ChartSpec spec;
  spec.width = 400;
  spec.height = 300;
  const Chart chart(spec);
  SvgCanvas canvas(400, 300, "", kTextColour);
  const Point at = chart.At(0.9, 0.5);
  DrawEndLabels(&canvas, chart,
                {{at, "first", kLineColour},
                 {{at.x, at.y + 1}, "second", kGoalColour},
                 {{at.x, at.y + 2}, "third", kAxisColour}});
  const std::string svg = canvas.Document();
  std::vector<double> ys = Attributes(svg, "text", "y");
  ASSERT_EQ(ys.size(), 3U);
  std::sort(ys.begin(), ys.end());
  EXPECT_GE(ys[1] - ys[0], 12);
  EXPECT_GE(ys[2] - ys[1], 12);
  for (double x : Attributes(svg, "text", "x")) EXPECT_DOUBLE_EQ(x, at.x - 5);
  EXPECT_NE(svg.find("paint-order=\"stroke\""), std::string::npos);  // a halo
}

TEST(ColourScaleTest, SpreadsThePaletteOverTheRangeAndClamps) {
  const Colour a = Colour::Hex(0x000000), b = Colour::Hex(0x808080), c = Colour::Hex(0xffffff);
  const ColourScale scale(10, 20, {a, b, c});
  EXPECT_EQ(scale(10), a);
  EXPECT_EQ(scale(15), b);
  EXPECT_EQ(scale(20), c);
  EXPECT_EQ(scale(-5), a);
  EXPECT_EQ(scale(99), c);
  const ColourScale one(3, 3, {a, b, c});  // one value: the middle colour
  EXPECT_EQ(one(3), b);
  EXPECT_EQ(one.lo(), 2.5);
  EXPECT_THROW(ColourScale(0, 1, {}), std::invalid_argument);
  EXPECT_EQ(Colour::Hex(0x1f6feb).ToHex(), "#1f6feb");
}

TEST(ColourBarTest, DrawsOneRowPerPixelWithTicksAndTitle) {
  SvgCanvas canvas(100, 200, "", kTextColour);
  Font font;
  font.size = 11;
  font.colour = kTextColour;
  DrawColourBar(&canvas, ColourScale(0, 1, {Colour::Hex(0), Colour::Hex(0xffffff)}), {10, 20}, 16,
                100, "value", font);
  const std::string svg = canvas.Document();
  EXPECT_NE(svg.find(">value<"), std::string::npos);
  EXPECT_NE(svg.find(">0.6<"), std::string::npos);
  // 100 rows, the top one white (high), the bottom one black; 6 ticks (0 to 1 by 0.2).
  EXPECT_NE(svg.find("y1=\"20.0\" x2=\"25.0\" y2=\"20.0\" fill=\"none\" stroke=\"#ffffff\""),
            std::string::npos);
  EXPECT_NE(svg.find("y1=\"119.0\" x2=\"25.0\" y2=\"119.0\" fill=\"none\" stroke=\"#000000\""),
            std::string::npos);
  EXPECT_EQ(Attributes(svg, "line", "x1").size(), 100U + 6U);
}

TEST(SquareMapTest, KeepsDistanceRatiosAndCentresTheData) {
  const Point data[] = {{0, 0}, {4, 0}, {4, 2}};
  const SquareMap map(data, {100, 50}, 200, 10);
  const Point a = map(data[0]), b = map(data[1]), c = map(data[2]);
  EXPECT_DOUBLE_EQ(b.x - a.x, 180);  // the longer extent fills the side less the margins
  EXPECT_DOUBLE_EQ(b.y - c.y, 90);   // the same scale for y, and y up
  EXPECT_DOUBLE_EQ((a.x + b.x) / 2, 200);
  EXPECT_DOUBLE_EQ((b.y + c.y) / 2, 150);
}

}  // namespace
}  // namespace rl::plot
