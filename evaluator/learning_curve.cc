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

// The legend's least room right of the title (or on a line of its own below it).
constexpr double kLegendWidth = 250;

// The overlay's line.
constexpr plot::Colour kOverlayColour = plot::Colour::Hex(0xbc4c00);

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
                     const std::vector<Point>& hi, const std::vector<CurvePoint>& overlay,
                     const CurveStyle& style, double title_width, double legend_width) {
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
    for (const CurvePoint& p : overlay) {
      spec.x_min = std::min(spec.x_min, p.x);
      spec.x_max = std::max(spec.x_max, p.x);
      spec.y_min = std::min(spec.y_min, p.mean);
      spec.y_max = std::max(spec.y_max, p.mean);
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
      plot::Chart::kLeft + title_width + 16 > style.width - plot::Chart::kRight - legend_width;
  spec.legend_height = legend_below ? 18 : 0;
  return spec;
}

// The legend's entries: the mean, its band, the overlay (when `overlay_label` is not empty) and
// the goal.
std::vector<plot::LegendEntry> LegendEntries(bool has_goal, const std::string& overlay_label) {
  std::vector<plot::LegendEntry> entries = {
      {plot::LegendEntry::Key::kLine, "mean", plot::Paint::Stroke(plot::kLineColour, 2)},
      {plot::LegendEntry::Key::kSwatch, "\xC2\xB1 1 std",
       plot::Paint::Fill(plot::kLineColour, 0.18)},
  };
  if (!overlay_label.empty()) {
    entries.push_back(
        {plot::LegendEntry::Key::kLine, overlay_label, plot::Paint::Stroke(kOverlayColour, 2)});
  }
  if (has_goal) {
    plot::Paint goal = plot::Paint::Stroke(plot::kGoalColour, 1.5);
    goal.dash = {5, 3};
    entries.push_back({plot::LegendEntry::Key::kLine, "goal", goal});
  }
  return entries;
}

// The line of the points' means (with their dots, when there are not too many), id `id`.
void DrawMeans(plot::Canvas* canvas, const plot::Chart& chart,
               const std::vector<CurvePoint>& points, plot::Colour colour, const char* id) {
  std::vector<Point> line;
  for (const CurvePoint& p : points) line.push_back(chart.At(p.x, p.mean));
  plot::Paint paint = plot::Paint::Stroke(colour, 2);
  paint.round_joins = true;
  canvas->Polyline(line, paint, {id, ""});
  if (points.size() <= 200) {
    for (const Point& p : line) canvas->Circle(p, 2.5, plot::Paint::Fill(colour));
  }
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
  DrawMeans(canvas, chart, points, plot::kLineColour, "mean");
}

}  // namespace

std::string RenderLearningCurveSvg(std::vector<CurvePoint> points, const CurveStyle& style,
                                   CurveOverlay overlay) {
  // Keep the finite points, in x order.
  std::erase_if(points, [](const CurvePoint& p) {
    return !std::isfinite(p.x) || !std::isfinite(p.mean) || !std::isfinite(p.std);
  });
  std::stable_sort(points.begin(), points.end(),
                   [](const CurvePoint& a, const CurvePoint& b) { return a.x < b.x; });
  std::erase_if(overlay.points,
                [](const CurvePoint& p) { return !std::isfinite(p.x) || !std::isfinite(p.mean); });
  std::stable_sort(overlay.points.begin(), overlay.points.end(),
                   [](const CurvePoint& a, const CurvePoint& b) { return a.x < b.x; });
  if (points.empty()) overlay.points.clear();
  std::vector<Point> lo, hi;
  BandEdges(points, &lo, &hi);
  const bool has_goal = std::isfinite(style.goal);

  plot::SvgCanvas canvas(style.width, style.height, style.title, plot::kTextColour);
  const std::vector<plot::LegendEntry> legend =
      LegendEntries(has_goal, overlay.points.empty() ? "" : overlay.label);
  const double legend_width = std::max(kLegendWidth, plot::LegendWidth(canvas, legend));
  const plot::Chart chart(
      Spec(points, lo, hi, overlay.points, style, canvas.TextWidth(style.title, 14), legend_width));
  plot::DrawLegend(&canvas,
                   {style.width - plot::Chart::kRight - legend_width,
                    chart.spec().legend_height > 0 ? 40.0 : 18.0},
                   legend);
  chart.DrawFrame(&canvas);
  if (points.empty()) {
    chart.DrawNote(&canvas, "no checkpoint scored yet");
  } else {
    DrawCurve(&canvas, chart, points, lo, hi);
  }
  if (!overlay.points.empty()) DrawMeans(&canvas, chart, overlay.points, kOverlayColour, "overlay");
  // The goal, dashed, labelled at its left end (where a learning curve is usually low).
  if (has_goal) {
    plot::Paint goal = plot::Paint::Stroke(plot::kGoalColour, 1.5);
    goal.dash = {6, 4};
    chart.DrawRule(&canvas, style.goal, "goal " + GoalLabel(style.goal), goal, {"goal", ""});
  }
  return canvas.Document();
}

}  // namespace rl::evaluator
