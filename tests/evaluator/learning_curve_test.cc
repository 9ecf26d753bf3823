#include "evaluator/learning_curve.h"

#include <cmath>
#include <string>
#include <vector>

#include <gtest/gtest.h>

namespace rl::evaluator {
namespace {

TEST(LearningCurveTest, DrawsLineBandGoalAndAxisTitles) {
  CurveStyle style;
  style.title = "return vs steps";
  style.x_label = "environment steps";
  style.goal = 475;
  const std::string svg =
      RenderLearningCurveSvg({{2000, 30, 5}, {1000, 10, 2}, {3000, 200, 50}}, style);
  EXPECT_EQ(svg.rfind("<svg xmlns=\"http://www.w3.org/2000/svg\"", 0), 0U);
  EXPECT_NE(svg.find("<polyline class=\"mean\""), std::string::npos);
  EXPECT_NE(svg.find("<path class=\"band\""), std::string::npos);
  EXPECT_NE(svg.find("<line class=\"goal\""), std::string::npos);
  EXPECT_NE(svg.find("environment steps"), std::string::npos);
  EXPECT_NE(svg.find("evaluation return"), std::string::npos);
  EXPECT_NE(svg.find(">3k<"), std::string::npos);   // an x tick label
  EXPECT_NE(svg.find(">500<"), std::string::npos);  // a y tick label
  EXPECT_NE(svg.find("</svg>"), std::string::npos);
  // Three points in x order: the polyline's x coordinates increase.
  const size_t at = svg.find("points=\"") + 8;
  const std::string pts = svg.substr(at, svg.find('"', at) - at);
  std::vector<double> xs;
  for (size_t p = 0; p < pts.size();) {
    xs.push_back(std::stod(pts.substr(p)));
    p = pts.find(' ', p);
    if (p == std::string::npos) break;
    ++p;
  }
  ASSERT_EQ(xs.size(), 3U);
  EXPECT_LT(xs[0], xs[1]);
  EXPECT_LT(xs[1], xs[2]);
}

TEST(LearningCurveTest, DrawsTheOverlaysLineWithItsLegendEntryAndRoomForIt) {
  CurveStyle style;
  style.goal = 475;
  const std::vector<CurvePoint> points = {{1000, 10, 2}, {2000, 30, 5}};
  const std::string plain = RenderLearningCurveSvg(points, style);
  EXPECT_EQ(plain.find("class=\"overlay\""), std::string::npos);
  EXPECT_EQ(plain.find("ensemble of 5"), std::string::npos);
  // The overlay's points above the curve's band widen the y axis to them.
  const std::string svg =
      RenderLearningCurveSvg(points, style, {"ensemble of 5", {{2000, 900}, {1000, 5}}});
  EXPECT_NE(svg.find("<polyline class=\"overlay\""), std::string::npos);
  EXPECT_NE(svg.find("ensemble of 5"), std::string::npos);
  EXPECT_NE(svg.find(">800<"), std::string::npos);  // a y tick label
  EXPECT_EQ(plain.find(">800<"), std::string::npos);
  // No curve: no overlay either.
  const std::string empty = RenderLearningCurveSvg({}, style, {"ensemble of 5", {{1, 2}}});
  EXPECT_EQ(empty.find("class=\"overlay\""), std::string::npos);
}

TEST(LearningCurveTest, PicksMinutesForLongDurations) {
  CurveStyle style;
  style.x_label = "wall time";
  style.x_kind = XAxisKind::kSeconds;
  style.goal = 475;
  const std::string svg = RenderLearningCurveSvg({{60, 10, 1}, {900, 100, 10}}, style);
  EXPECT_NE(svg.find("wall time (min)"), std::string::npos);
  const std::string short_run = RenderLearningCurveSvg({{5, 10, 1}, {50, 100, 10}}, style);
  EXPECT_NE(short_run.find("wall time (s)"), std::string::npos);
}

TEST(LearningCurveTest, LeavesOutNonFinitePointsAndHandlesNoPoints) {
  CurveStyle style;
  style.goal = std::nan("");
  const std::string svg = RenderLearningCurveSvg({{1, std::nan(""), 0}}, style);
  EXPECT_EQ(svg.find("<polyline"), std::string::npos);
  EXPECT_EQ(svg.find("class=\"goal\""), std::string::npos);
  EXPECT_NE(svg.find("no checkpoint scored yet"), std::string::npos);
  EXPECT_EQ(svg.find("nan"), std::string::npos);
}

}  // namespace
}  // namespace rl::evaluator
