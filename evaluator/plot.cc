#include "evaluator/plot.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <utility>

namespace rl::plot {
namespace {

// Text sizes of the frames: title, tick labels and legends, axis titles.
constexpr double kTitleSize = 14;
constexpr double kSmallSize = 11;
constexpr double kLabelSize = 12;

Font SmallFont(Colour colour, Anchor anchor = Anchor::kStart) {
  Font f;
  f.size = kSmallSize;
  f.colour = colour;
  f.anchor = anchor;
  return f;
}

}  // namespace

std::string FormatNumber(const char* fmt, double v) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), fmt, v);
  return buf;
}

std::string Colour::ToHex() const {
  char buf[8];
  std::snprintf(buf, sizeof(buf), "#%02x%02x%02x", r, g, b);
  return buf;
}

Paint Paint::Stroke(Colour colour, double width) {
  Paint p;
  p.stroke = colour;
  p.stroke_width = width;
  return p;
}

Paint Paint::Fill(Colour colour, double opacity) {
  Paint p;
  p.fill = colour;
  p.fill_opacity = opacity;
  return p;
}

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

std::string FormatTick(double v, TickFormat format) {
  if (std::abs(v) < 1e-9) v = 0;
  if (format == TickFormat::kCount) {
    const double a = std::abs(v);
    if (a >= 1e9) return FormatTick(v / 1e9, TickFormat::kPlain) + "G";
    if (a >= 1e6) return FormatTick(v / 1e6, TickFormat::kPlain) + "M";
    if (a >= 1e3) return FormatTick(v / 1e3, TickFormat::kPlain) + "k";
  }
  return FormatNumber(std::abs(v) < 1e15 && v == std::round(v) ? "%.0f" : "%.3g", v);
}

TimeUnit PickTimeUnit(double max_seconds) {
  if (max_seconds >= 2 * 3600.0) return {3600, "h"};
  if (max_seconds >= 120.0) return {60, "min"};
  return {1, "s"};
}

Chart::Chart(ChartSpec spec) : spec_(std::move(spec)) {
  if (!(spec_.x_unit > 0)) throw std::invalid_argument("chart: x unit must be positive");
  x_ticks_ = NiceTicks(spec_.x_min / spec_.x_unit, spec_.x_max / spec_.x_unit, spec_.x_ticks);
  y_ticks_ = NiceTicks(spec_.y_min, spec_.y_max, spec_.y_ticks);
  if (x_ticks_.empty()) x_ticks_ = {0, 1};
  if (y_ticks_.empty()) y_ticks_ = {0, 1};
  const double w = spec_.width, h = spec_.height;
  x_ = {x_ticks_.front() * spec_.x_unit, x_ticks_.back() * spec_.x_unit, kLeft, w - kRight};
  y_ = {y_ticks_.front(), y_ticks_.back(), h - kBottom, kTop + spec_.legend_height};
}

std::vector<Point> Chart::At(std::span<const Point> data) const {
  std::vector<Point> pixels;
  pixels.reserve(data.size());
  for (const Point& p : data) pixels.push_back(At(p));
  return pixels;
}

void Chart::DrawFrame(Canvas* canvas) const {
  Font title;
  title.size = kTitleSize;
  title.colour = kTextColour;
  title.bold = true;
  canvas->Text({kLeft, 22}, spec_.title, title);

  // Grid lines, then the tick labels.
  const Paint grid = Paint::Stroke(kGridColour);
  for (double t : x_ticks_) {
    const double px = x_(t * spec_.x_unit);
    canvas->Line({px, y_.p1}, {px, y_.p0}, grid);
  }
  for (double t : y_ticks_) canvas->Line({x_.p0, y_(t)}, {x_.p1, y_(t)}, grid);
  for (double t : x_ticks_) {
    canvas->Text({x_(t * spec_.x_unit), y_.p0 + 16}, FormatTick(t, spec_.x_format),
                 SmallFont(kAxisColour, Anchor::kMiddle));
  }
  for (double t : y_ticks_) {
    canvas->Text({x_.p0 - 8, y_(t) + 4}, FormatTick(t, TickFormat::kPlain),
                 SmallFont(kAxisColour, Anchor::kEnd));
  }

  // The axes and their titles.
  const Point axes[] = {{x_.p0, y_.p1}, {x_.p0, y_.p0}, {x_.p1, y_.p0}};
  canvas->Path(axes, false, Paint::Stroke(kAxisColour));
  Font label;
  label.size = kLabelSize;
  label.colour = kTextColour;
  label.anchor = Anchor::kMiddle;
  canvas->Text({(x_.p0 + x_.p1) / 2, spec_.height - 14.0}, spec_.x_label, label);
  label.rotation = -90;
  canvas->Text({18, (y_.p0 + y_.p1) / 2}, spec_.y_label, label);
}

void Chart::DrawRule(Canvas* canvas, double y, const std::string& label, const Paint& paint,
                     const Mark& mark) const {
  const double py = y_(y);
  canvas->Line({x_.p0, py}, {x_.p1, py}, paint, mark);
  canvas->Text({x_.p0 + 6, py - 5}, label, SmallFont(paint.stroke.value_or(kTextColour)));
}

void Chart::DrawNote(Canvas* canvas, const std::string& text) const {
  Font font;
  font.size = kLabelSize;
  font.colour = kAxisColour;
  font.anchor = Anchor::kMiddle;
  canvas->Text({(x_.p0 + x_.p1) / 2, (y_.p0 + y_.p1) / 2}, text, font);
}

// A legend entry's key, the gap after it, and the gap after its label.
constexpr double kLegendKey = 18;
constexpr double kLegendKeyGap = 4;
constexpr double kLegendEntryGap = 16;

void DrawLegend(Canvas* canvas, Point at, std::span<const LegendEntry> entries) {
  constexpr double kKey = kLegendKey;
  double x = at.x;
  for (const LegendEntry& e : entries) {
    if (e.key == LegendEntry::Key::kLine) {
      canvas->Line({x, at.y}, {x + kKey, at.y}, e.paint);
    } else {
      canvas->Rect({x, at.y - 6}, kKey, 12, e.paint);
    }
    canvas->Text({x + kKey + kLegendKeyGap, at.y + 4}, e.label, SmallFont(kTextColour));
    x += kKey + kLegendKeyGap + canvas->TextWidth(e.label, kSmallSize) + kLegendEntryGap;
  }
}

double LegendWidth(const Canvas& canvas, std::span<const LegendEntry> entries) {
  double width = 0;
  for (const LegendEntry& e : entries) {
    width += kLegendKey + kLegendKeyGap + canvas.TextWidth(e.label, kSmallSize) + kLegendEntryGap;
  }
  return entries.empty() ? 0 : width - kLegendEntryGap;
}

std::vector<Point> StepCorners(std::span<const Point> points) {
  std::vector<Point> corners;
  for (size_t i = 0; i < points.size(); ++i) {
    if (i > 0) corners.push_back({points[i].x, points[i - 1].y});
    corners.push_back(points[i]);
  }
  return corners;
}

std::vector<Point> StepBand(std::span<const Point> upper, std::span<const Point> lower) {
  std::vector<Point> band = StepCorners(upper);
  const std::vector<Point> back = StepCorners(lower);
  band.insert(band.end(), back.rbegin(), back.rend());
  return band;
}

void DrawEndLabels(Canvas* canvas, const Chart& chart, std::vector<EndLabel> labels) {
  std::stable_sort(labels.begin(), labels.end(),
                   [](const EndLabel& a, const EndLabel& b) { return a.at.y < b.at.y; });
  struct Placed {
    double left, right, baseline;
  };
  std::vector<Placed> placed;
  const double top = chart.y().p1, bottom = chart.y().p0;
  for (const EndLabel& l : labels) {
    const double right = l.at.x - 5, left = right - canvas->TextWidth(l.text, kSmallSize);
    const auto free = [&](double y) {
      if (y < top - 6 || y > bottom - 3) return false;
      return std::none_of(placed.begin(), placed.end(), [&](const Placed& p) {
        return left < p.right && p.left < right && std::abs(p.baseline - y) < 12;
      });
    };
    double y = l.at.y - 6;
    for (int k = 0; k < 40; ++k) {
      // Above at -6, -19, -32, ...; below at +15, +28, ...
      const double candidate =
          k % 2 == 0 ? l.at.y - 6 - 13.0 * (k / 2) : l.at.y + 15 + 13.0 * (k / 2);
      if (free(candidate)) {
        y = candidate;
        break;
      }
    }
    placed.push_back({left, right, y});
    Font font = SmallFont(l.colour, Anchor::kEnd);
    font.halo = kWhite;
    canvas->Text({right, y}, l.text, font);
  }
}

ColourScale::ColourScale(double lo, double hi, std::vector<Colour> palette)
    : lo_(lo), hi_(hi), palette_(std::move(palette)) {
  if (palette_.empty()) throw std::invalid_argument("colour scale: no colours");
  if (!std::isfinite(lo) || !std::isfinite(hi)) {
    throw std::invalid_argument("colour scale: bounds must be finite");
  }
  if (hi_ < lo_) std::swap(lo_, hi_);
  if (!(hi_ > lo_)) {
    lo_ -= 0.5;
    hi_ += 0.5;
  }
}

Colour ColourScale::operator()(double v) const {
  const double t = std::clamp((v - lo_) / (hi_ - lo_), 0.0, 1.0);
  return palette_[static_cast<size_t>(std::lround(t * static_cast<double>(palette_.size() - 1)))];
}

void DrawColourBar(Canvas* canvas, const ColourScale& scale, Point corner, double width,
                   double height, const std::string& title, const Font& font) {
  const double lo = scale.lo(), hi = scale.hi();
  const int rows = std::max(2, static_cast<int>(std::lround(height)));
  for (int r = 0; r < rows; ++r) {
    Paint row = Paint::Stroke(scale(hi - (hi - lo) * r / (rows - 1)));
    row.crisp = true;
    canvas->Line({corner.x, corner.y + r}, {corner.x + width - 1, corner.y + r}, row);
  }
  Paint ink = Paint::Stroke(font.colour);
  ink.crisp = true;
  canvas->Rect(corner, width, height, ink);
  for (double t : NiceTicks(lo, hi, 6)) {
    if (t < lo || t > hi) continue;
    const double y = corner.y + std::round((hi - t) / (hi - lo) * (rows - 1));
    canvas->Line({corner.x + width, y}, {corner.x + width + 4, y}, ink);
    canvas->Text({corner.x + width + 7, y + 5},
                 FormatNumber("%.3g", std::abs(t) < 1e-12 * (hi - lo) ? 0.0 : t), font);
  }
  canvas->Text({corner.x - 8, corner.y - 8}, title, font);
}

SquareMap::SquareMap(std::span<const Point> data, Point corner, double side, double margin) {
  double x_min = 0, x_max = 0, y_min = 0, y_max = 0;
  for (size_t i = 0; i < data.size(); ++i) {
    const Point& p = data[i];
    x_min = i == 0 ? p.x : std::min(x_min, p.x);
    x_max = i == 0 ? p.x : std::max(x_max, p.x);
    y_min = i == 0 ? p.y : std::min(y_min, p.y);
    y_max = i == 0 ? p.y : std::max(y_max, p.y);
  }
  const double span = std::max({x_max - x_min, y_max - y_min, 1e-12});
  pixels_per_unit_ = (side - 2 * margin) / span;
  centre_data_ = {(x_min + x_max) / 2, (y_min + y_max) / 2};
  centre_pixels_ = {corner.x + side / 2, corner.y + side / 2};
}

Point SquareMap::operator()(Point data) const {
  return {centre_pixels_.x + (data.x - centre_data_.x) * pixels_per_unit_,
          centre_pixels_.y - (data.y - centre_data_.y) * pixels_per_unit_};
}

}  // namespace rl::plot
