#include "evaluator/learning_curve.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <utility>

#include "evaluator/plot.h"
#include "evaluator/svg_canvas.h"

namespace rl::evaluator {
namespace {

using plot::Point;

// The legend's room right of the title (or on a line of its own below it).
constexpr double kLegendWidth = 250;

// The goal's value, e.g. 475 or 195.5.
std::string GoalLabel(double v) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%.6g", v);
  return buf;
}

// The points' band edges: plus/minus one std, clipped to the observed returns.
void BandEdges(const std::vector<CurvePoint>& points, std::vector<Point>* lo,
               std::vector<Point>* hi) {
  for (const CurvePoint& p : points) {
    double l = p.mean - p.std, h = p.mean + p.std;
    if (std::isfinite(p.min)) l = std::max(l, std::min(p.min, p.mean));
    if (std::isfinite(p.max)) h = std::min(h, std::max(p.max, p.mean));
    lo->push_back({p.x, l});
    hi->push_back({p.x, h});
  }
}

// The chart: x from 0 (or below), y covering the band, 0 and the goal; the legend right of the
// title when both fit on one line, else below it.
plot::ChartSpec Spec(const std::vector<CurvePoint>& points, const std::vector<Point>& lo,
                     const std::vector<Point>& hi, const CurveStyle& style, double title_width) {
  const bool has_goal = std::isfinite(style.goal);
  plot::ChartSpec spec;
  spec.width = style.width;
  spec.height = style.height;
  spec.title = style.title;
  spec.x_label = style.x_label;
  spec.y_label = style.y_label;
  spec.x_min = 0;
  spec.x_max = 1;
  spec.y_min = 0;
  spec.y_max = 1;
  if (!points.empty()) {
    spec.x_min = std::min(0.0, points.front().x);
    spec.x_max = points.back().x;
    spec.y_max = has_goal ? style.goal : points.front().mean;
    for (size_t i = 0; i < points.size(); ++i) {
      spec.y_min = std::min(spec.y_min, lo[i].y);
      spec.y_max = std::max(spec.y_max, hi[i].y);
    }
  } else if (has_goal) {
    spec.y_max = std::max(style.goal, 1.0);
  }
  if (has_goal) spec.y_min = std::min(spec.y_min, style.goal);
  if (style.x_kind == XAxisKind::kSeconds) {
    const plot::TimeUnit unit = plot::PickTimeUnit(points.empty() ? 0.0 : points.back().x);
    spec.x_unit = unit.seconds;
    spec.x_label += " (" + unit.name + ")";
  } else {
    spec.x_format = plot::TickFormat::kCount;
  }
  const bool legend_below =
      plot::Chart::kLeft + title_width + 16 > style.width - plot::Chart::kRight - kLegendWidth;
  spec.legend_height = legend_below ? 18 : 0;
  return spec;
}

void DrawLegend(plot::Canvas* canvas, const plot::Chart& chart, bool has_goal) {
  std::vector<plot::LegendEntry> entries = {
      {plot::LegendEntry::Key::kLine, "mean", plot::Paint::Stroke(plot::kLineColour, 2)},
      {plot::LegendEntry::Key::kSwatch, "\xC2\xB1 1 std",
       plot::Paint::Fill(plot::kLineColour, 0.18)},
  };
  if (has_goal) {
    plot::Paint goal = plot::Paint::Stroke(plot::kGoalColour, 1.5);
    goal.dash = {5, 3};
    entries.push_back({plot::LegendEntry::Key::kLine, "goal", goal});
  }
  const double y = chart.spec().legend_height > 0 ? 40 : 18;
  plot::DrawLegend(canvas, {chart.spec().width - plot::Chart::kRight - kLegendWidth, y}, entries);
}

// The band of plus/minus one std, then the mean line and its points.
void DrawCurve(plot::Canvas* canvas, const plot::Chart& chart,
               const std::vector<CurvePoint>& points, const std::vector<Point>& lo,
               const std::vector<Point>& hi) {
  std::vector<Point> band = chart.At(hi);
  for (size_t i = lo.size(); i-- > 0;) band.push_back(chart.At(lo[i]));
  plot::Paint band_paint = plot::Paint::Fill(plot::kLineColour, 0.18);
  band_paint.stroke = plot::kLineColour;
  band_paint.stroke_opacity = 0.35;
  band_paint.stroke_width = 0.8;
  canvas->Path(band, true, band_paint, {"band", ""});
  std::vector<Point> line;
  for (const CurvePoint& p : points) line.push_back(chart.At(p.x, p.mean));
  plot::Paint line_paint = plot::Paint::Stroke(plot::kLineColour, 2);
  line_paint.round_joins = true;
  canvas->Polyline(line, line_paint, {"mean", ""});
  if (points.size() <= 200) {
    for (const Point& p : line) canvas->Circle(p, 2.5, plot::Paint::Fill(plot::kLineColour));
  }
}

}  // namespace

std::string RenderLearningCurveSvg(std::vector<CurvePoint> points, const CurveStyle& style) {
  // Keep the finite points, in x order.
  std::erase_if(points, [](const CurvePoint& p) {
    return !std::isfinite(p.x) || !std::isfinite(p.mean) || !std::isfinite(p.std);
  });
  std::stable_sort(points.begin(), points.end(),
                   [](const CurvePoint& a, const CurvePoint& b) { return a.x < b.x; });
  std::vector<Point> lo, hi;
  BandEdges(points, &lo, &hi);
  const bool has_goal = std::isfinite(style.goal);

  plot::SvgCanvas canvas(style.width, style.height, style.title, plot::kTextColour);
  const plot::Chart chart(Spec(points, lo, hi, style, canvas.TextWidth(style.title, 14)));
  DrawLegend(&canvas, chart, has_goal);
  chart.DrawFrame(&canvas);
  if (points.empty()) {
    chart.DrawNote(&canvas, "no checkpoint scored yet");
  } else {
    DrawCurve(&canvas, chart, points, lo, hi);
  }
  // The goal, dashed, labelled at its left end (where a learning curve is usually low).
  if (has_goal) {
    plot::Paint goal = plot::Paint::Stroke(plot::kGoalColour, 1.5);
    goal.dash = {6, 4};
    chart.DrawRule(&canvas, style.goal, "goal " + GoalLabel(style.goal), goal, {"goal", ""});
  }
  return canvas.Document();
}

}  // namespace rl::evaluator
