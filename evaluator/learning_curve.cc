#include "evaluator/learning_curve.h"

#include "evaluator/report.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <utility>

namespace rl::evaluator {
namespace {

// Colours of the curve, its band and the goal line.
constexpr char kLineColor[] = "#1f6feb";
constexpr char kBandColor[] = "#1f6feb";
constexpr char kGoalColor[] = "#d1242f";
constexpr char kGridColor[] = "#e6e8eb";
constexpr char kAxisColor[] = "#57606a";
constexpr char kTextColor[] = "#24292f";

// Margins around the plot area, in pixels.
constexpr double kLeft = 72;
constexpr double kRight = 24;
constexpr double kTop = 40;
constexpr double kBottom = 56;

// A coordinate with one decimal.
std::string Num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%.1f", v);
  return buf;
}

// A tick value: whole numbers in full (500, 1200), others with at most three significant digits.
std::string Plain(double v) {
  if (std::abs(v) < 1e-9) v = 0;
  char buf[32];
  if (std::abs(v) < 1e15 && v == std::round(v)) {
    std::snprintf(buf, sizeof(buf), "%.0f", v);
  } else {
    std::snprintf(buf, sizeof(buf), "%.3g", v);
  }
  return buf;
}

// The goal's value, e.g. 475 or 195.5.
std::string GoalLabel(double v) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%.6g", v);
  return buf;
}

// A count tick: 0, 800, 50k, 1.5M, 2G.
std::string CountLabel(double v) {
  const double a = std::abs(v);
  if (a >= 1e9) return Plain(v / 1e9) + "G";
  if (a >= 1e6) return Plain(v / 1e6) + "M";
  if (a >= 1e4) return Plain(v / 1e3) + "k";
  if (a >= 1e3 && std::fmod(a, 1e3) == 0) return Plain(v / 1e3) + "k";
  return Plain(v);
}

// Maps [lo, hi] to pixels [p0, p1].
struct Scale {
  double lo, hi, p0, p1;
  double operator()(double v) const { return p0 + (v - lo) / (hi - lo) * (p1 - p0); }
};

}  // namespace

std::vector<double> NiceTicks(double lo, double hi, int target) {
  if (!std::isfinite(lo) || !std::isfinite(hi)) return {};
  if (hi < lo) std::swap(lo, hi);
  if (hi - lo < 1e-12 * std::max(1.0, std::abs(hi))) {
    lo -= 0.5;
    hi += 0.5;
  }
  target = std::max(target, 1);
  // Round the raw step to the nearest of 1, 2, 5 or 10 times a power of ten.
  const double raw = (hi - lo) / target;
  const double magnitude = std::pow(10.0, std::floor(std::log10(raw)));
  const double norm = raw / magnitude;
  const double step = (norm < 1.5 ? 1.0 : norm < 3.0 ? 2.0 : norm < 7.0 ? 5.0 : 10.0) * magnitude;
  // First tick at or below lo, last at or above hi.
  const double first = std::floor(lo / step + 1e-9);
  const double last = std::ceil(hi / step - 1e-9);
  std::vector<double> ticks;
  for (double k = first; k <= last; k += 1.0) ticks.push_back(k * step);
  return ticks;
}

std::string RenderLearningCurveSvg(std::vector<CurvePoint> points, const CurveStyle& style) {
  // Keep the finite points, in x order.
  std::erase_if(points, [](const CurvePoint& p) {
    return !std::isfinite(p.x) || !std::isfinite(p.mean) || !std::isfinite(p.std);
  });
  std::stable_sort(points.begin(), points.end(),
                   [](const CurvePoint& a, const CurvePoint& b) { return a.x < b.x; });
  // The band's edges, clipped to the observed returns.
  std::vector<double> band_lo, band_hi;
  for (const CurvePoint& p : points) {
    double lo = p.mean - p.std, hi = p.mean + p.std;
    if (std::isfinite(p.min)) lo = std::max(lo, std::min(p.min, p.mean));
    if (std::isfinite(p.max)) hi = std::min(hi, std::max(p.max, p.mean));
    band_lo.push_back(lo);
    band_hi.push_back(hi);
  }
  const bool has_goal = std::isfinite(style.goal);

  // Pick the unit of a duration axis from the range, and scale x into it.
  std::string x_label = style.x_label;
  if (style.x_kind == XAxisKind::kSeconds) {
    double x_max = 0;
    for (const CurvePoint& p : points) x_max = std::max(x_max, p.x);
    double unit = 1;
    std::string unit_name = "s";
    if (x_max >= 2 * 3600.0) {
      unit = 3600;
      unit_name = "h";
    } else if (x_max >= 120.0) {
      unit = 60;
      unit_name = "min";
    }
    for (CurvePoint& p : points) p.x /= unit;
    x_label += " (" + unit_name + ")";
  }

  // Data ranges: x from 0 (or below), y covering the band, 0 and the goal.
  double x_lo = 0, x_hi = 1, y_lo = 0, y_hi = 1;
  if (!points.empty()) {
    x_lo = std::min(0.0, points.front().x);
    x_hi = points.back().x;
    y_hi = has_goal ? style.goal : points.front().mean;
    for (size_t i = 0; i < points.size(); ++i) {
      y_lo = std::min(y_lo, band_lo[i]);
      y_hi = std::max(y_hi, band_hi[i]);
    }
  } else if (has_goal) {
    y_hi = std::max(style.goal, 1.0);
  }
  if (has_goal) y_lo = std::min(y_lo, style.goal);
  const std::vector<double> x_ticks = NiceTicks(x_lo, x_hi, 6);
  const std::vector<double> y_ticks = NiceTicks(y_lo, y_hi, 5);

  const double w = style.width, h = style.height;
  const Scale sx{x_ticks.front(), x_ticks.back(), kLeft, w - kRight};
  // The legend sits right of the title when both fit on one line (about 7.5 px per character of
  // the 14 px title), else on a line of its own below it.
  const double legend_width = 250;
  const bool legend_below =
      kLeft + 7.5 * static_cast<double>(style.title.size()) + 16 > w - kRight - legend_width;
  const double top = legend_below ? kTop + 18 : kTop;
  const Scale sy{y_ticks.front(), y_ticks.back(), h - kBottom, top};

  std::string s;
  s += "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" + std::to_string(style.width) +
       "\" height=\"" + std::to_string(style.height) + "\" viewBox=\"0 0 " +
       std::to_string(style.width) + " " + std::to_string(style.height) +
       "\" font-family=\"-apple-system, 'Segoe UI', Helvetica, Arial, sans-serif\" "
       "font-size=\"12\" fill=\"" +
       kTextColor + "\">\n";
  s += "<title>" + HtmlEscape(style.title) + "</title>\n";
  s += "<rect width=\"100%\" height=\"100%\" fill=\"#ffffff\"/>\n";
  s += "<text x=\"" + Num(kLeft) + "\" y=\"22\" font-size=\"14\" font-weight=\"600\">" +
       HtmlEscape(style.title) + "</text>\n";

  // Legend, top right.
  {
    const double y = legend_below ? 40 : 18;
    double x = w - kRight - legend_width;
    s += "<g font-size=\"11\">";
    s += "<line x1=\"" + Num(x) + "\" y1=\"" + Num(y) + "\" x2=\"" + Num(x + 18) + "\" y2=\"" +
         Num(y) + "\" stroke=\"" + kLineColor + "\" stroke-width=\"2\"/>";
    s += "<text x=\"" + Num(x + 22) + "\" y=\"" + Num(y + 4) + "\">mean</text>";
    x += 62;
    s += "<rect x=\"" + Num(x) + "\" y=\"" + Num(y - 6) + "\" width=\"18\" height=\"12\" fill=\"" +
         kBandColor + "\" fill-opacity=\"0.18\"/>";
    s += "<text x=\"" + Num(x + 22) + "\" y=\"" + Num(y + 4) + "\">\xC2\xB1 1 std</text>";
    x += 80;
    if (has_goal) {
      s += "<line x1=\"" + Num(x) + "\" y1=\"" + Num(y) + "\" x2=\"" + Num(x + 18) + "\" y2=\"" +
           Num(y) + "\" stroke=\"" + kGoalColor + "\" stroke-width=\"1.5\" " +
           "stroke-dasharray=\"5 3\"/>";
      s += "<text x=\"" + Num(x + 22) + "\" y=\"" + Num(y + 4) + "\">goal</text>";
    }
    s += "</g>\n";
  }

  // Grid lines and tick labels.
  s += "<g stroke=\"" + std::string(kGridColor) + "\" stroke-width=\"1\">";
  for (double t : x_ticks) {
    s += "<line x1=\"" + Num(sx(t)) + "\" y1=\"" + Num(sy.p1) + "\" x2=\"" + Num(sx(t)) +
         "\" y2=\"" + Num(sy.p0) + "\"/>";
  }
  for (double t : y_ticks) {
    s += "<line x1=\"" + Num(sx.p0) + "\" y1=\"" + Num(sy(t)) + "\" x2=\"" + Num(sx.p1) +
         "\" y2=\"" + Num(sy(t)) + "\"/>";
  }
  s += "</g>\n";
  s += "<g font-size=\"11\" fill=\"" + std::string(kAxisColor) + "\">";
  for (double t : x_ticks) {
    const std::string label = style.x_kind == XAxisKind::kCount ? CountLabel(t) : Plain(t);
    s += "<text x=\"" + Num(sx(t)) + "\" y=\"" + Num(sy.p0 + 16) + "\" text-anchor=\"middle\">" +
         HtmlEscape(label) + "</text>";
  }
  for (double t : y_ticks) {
    s += "<text x=\"" + Num(sx.p0 - 8) + "\" y=\"" + Num(sy(t) + 4) + "\" text-anchor=\"end\">" +
         HtmlEscape(Plain(t)) + "</text>";
  }
  s += "</g>\n";

  // Axes and their titles.
  s += "<path d=\"M" + Num(sx.p0) + "," + Num(sy.p1) + " V" + Num(sy.p0) + " H" + Num(sx.p1) +
       "\" fill=\"none\" stroke=\"" + kAxisColor + "\" stroke-width=\"1\"/>\n";
  s += "<text x=\"" + Num((sx.p0 + sx.p1) / 2) + "\" y=\"" + Num(h - 14) +
       "\" text-anchor=\"middle\">" + HtmlEscape(x_label) + "</text>\n";
  s += "<text transform=\"translate(18," + Num((sy.p0 + sy.p1) / 2) +
       ") rotate(-90)\" text-anchor=\"middle\">" + HtmlEscape(style.y_label) + "</text>\n";

  // The band of plus/minus one std, then the mean line and its points.
  if (!points.empty()) {
    std::string band = "M";
    for (size_t i = 0; i < points.size(); ++i) {
      if (i > 0) band += " L";
      band += Num(sx(points[i].x)) + "," + Num(sy(band_hi[i]));
    }
    for (size_t i = points.size(); i-- > 0;) {
      band += " L" + Num(sx(points[i].x)) + "," + Num(sy(band_lo[i]));
    }
    band += " Z";
    s += "<path class=\"band\" d=\"" + band + "\" fill=\"" + kBandColor +
         "\" fill-opacity=\"0.18\" stroke=\"" + kBandColor +
         "\" stroke-opacity=\"0.35\" stroke-width=\"0.8\"/>\n";
    std::string line;
    for (const CurvePoint& p : points) {
      if (!line.empty()) line += " ";
      line += Num(sx(p.x)) + "," + Num(sy(p.mean));
    }
    s += "<polyline class=\"mean\" points=\"" + line + "\" fill=\"none\" stroke=\"" + kLineColor +
         "\" stroke-width=\"2\" stroke-linejoin=\"round\"/>\n";
    if (points.size() <= 200) {
      s += "<g fill=\"" + std::string(kLineColor) + "\">";
      for (const CurvePoint& p : points) {
        s += "<circle cx=\"" + Num(sx(p.x)) + "\" cy=\"" + Num(sy(p.mean)) + "\" r=\"2.5\"/>";
      }
      s += "</g>\n";
    }
  } else {
    s += "<text x=\"" + Num((sx.p0 + sx.p1) / 2) + "\" y=\"" + Num((sy.p0 + sy.p1) / 2) +
         "\" text-anchor=\"middle\" fill=\"" + kAxisColor + "\">no checkpoint scored yet</text>\n";
  }

  // The goal, dashed, labelled at its left end (where a learning curve is usually low).
  if (has_goal) {
    const double gy = sy(style.goal);
    s += "<line class=\"goal\" x1=\"" + Num(sx.p0) + "\" y1=\"" + Num(gy) + "\" x2=\"" +
         Num(sx.p1) + "\" y2=\"" + Num(gy) + "\" stroke=\"" + kGoalColor +
         "\" stroke-width=\"1.5\" stroke-dasharray=\"6 4\"/>\n";
    s += "<text x=\"" + Num(sx.p0 + 6) + "\" y=\"" + Num(gy - 5) + "\" font-size=\"11\" fill=\"" +
         kGoalColor + "\">goal " + HtmlEscape(GoalLabel(style.goal)) + "</text>\n";
  }
  s += "</svg>\n";
  return s;
}

}  // namespace rl::evaluator
