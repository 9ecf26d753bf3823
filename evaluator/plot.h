// The plotting module of the report (learning and training curves), the compare page (runs'
// curves) and the t-SNE map: scales and round ticks, a chart frame (title, grid, tick labels,
// axes and their titles), legends, reference lines, step functions and bands, labels at line
// ends, colour scales and colour bars. It draws on a Canvas (canvas.h): SvgCanvas for the
// pages, a raster canvas for the t-SNE map's PNG. No third-party dependency.
#pragma once

#include <span>
#include <string>
#include <vector>

#include "evaluator/canvas.h"

namespace rl::plot {

/// The colours of the pages: text, axes and tick labels, grid, the goal, the main line.
inline constexpr Colour kTextColour = Colour::Hex(0x24292f);
inline constexpr Colour kAxisColour = Colour::Hex(0x57606a);
inline constexpr Colour kGridColour = Colour::Hex(0xe6e8eb);
inline constexpr Colour kGoalColour = Colour::Hex(0xd1242f);
inline constexpr Colour kLineColour = Colour::Hex(0x1f6feb);
inline constexpr Colour kWhite = Colour::Hex(0xffffff);

/// Up to about `target` round tick values (1, 2 or 5 times a power of ten) covering [lo, hi]:
/// the first at or below lo, the last at or above hi. An empty range is widened by 0.5 each side;
/// a non-finite bound gives no ticks.
std::vector<double> NiceTicks(double lo, double hi, int target);

/// Maps [lo, hi] linearly to pixels [p0, p1].
struct Scale {
  double lo = 0, hi = 1, p0 = 0, p1 = 1;
  double operator()(double v) const { return p0 + (v - lo) / (hi - lo) * (p1 - p0); }
};

/// How tick values are written.
enum class TickFormat {
  kPlain,  // whole numbers in full (500, 1200), others with at most three significant digits
  kCount,  // counts: 0, 800, 1.5k, 50k, 1.5M, 2G
};
std::string FormatTick(double v, TickFormat format);

/// `v` printed with the printf format `fmt` (one double conversion, e.g. "%.1f"), up to 31
/// characters.
std::string FormatNumber(const char* fmt, double v);

/// The unit of a duration axis: seconds, minutes from 2 minutes, hours from 2 hours.
struct TimeUnit {
  double seconds = 1;  // the unit in seconds
  std::string name;    // "s", "min" or "h"
};
TimeUnit PickTimeUnit(double max_seconds);

/// What a chart's frame shows and the data range its axes cover.
struct ChartSpec {
  int width = 720;  // pixels
  int height = 380;
  std::string title;    // above the plot
  std::string x_label;  // axis titles
  std::string y_label;
  double x_min = 0, x_max = 1;  // data the axes cover (ticks are rounded outwards)
  double y_min = 0, y_max = 1;
  int x_ticks = 6;  // about this many ticks
  int y_ticks = 5;
  TickFormat x_format = TickFormat::kPlain;
  double x_unit = 1;         // tick labels show x / x_unit (60: minutes of data in seconds)
  double legend_height = 0;  // room between the title and the plot for a line of legend
};

/// A chart: the plot area inside fixed margins, its scales from data to pixels and its frame.
class Chart {
 public:
  /// Margins around the plot area, in pixels (the title and legend sit in the top one).
  static constexpr double kLeft = 72, kRight = 24, kTop = 40, kBottom = 56;

  explicit Chart(ChartSpec spec);
  const ChartSpec& spec() const { return spec_; }
  /// Data to pixels, x and y (the y scale runs up).
  const Scale& x() const { return x_; }
  const Scale& y() const { return y_; }
  Point At(double x, double y) const { return {x_(x), y_(y)}; }
  Point At(Point data) const { return At(data.x, data.y); }
  std::vector<Point> At(std::span<const Point> data) const;

  /// The title, grid lines, tick labels, axes and axis titles.
  void DrawFrame(Canvas* canvas) const;
  /// A dashed level line at data y across the plot area with `label` at its left end.
  void DrawRule(Canvas* canvas, double y, const std::string& label, const Paint& paint,
                const Mark& mark) const;
  /// `text` in the middle of the plot area (a plot without data says why).
  void DrawNote(Canvas* canvas, const std::string& text) const;

 private:
  ChartSpec spec_;
  std::vector<double> x_ticks_;  // in x / x_unit
  std::vector<double> y_ticks_;
  Scale x_;
  Scale y_;
};

/// One entry of a legend: a key (a short line or a filled swatch, in `paint`) and its label.
struct LegendEntry {
  enum class Key { kLine, kSwatch };
  Key key = Key::kLine;
  std::string label;
  Paint paint;
};

/// The entries side by side from `at` (the left end of the first key, at the keys' middle
/// height): an 18 px key, its label in 11 px, 16 px to the next entry.
void DrawLegend(Canvas* canvas, Point at, std::span<const LegendEntry> entries);
/// The width DrawLegend gives `entries` on `canvas`.
double LegendWidth(const Canvas& canvas, std::span<const LegendEntry> entries);

/// The corners of a step function through `points` (x ascending, each y holding until the next
/// point's x): (x0, y0), (x1, y0), (x1, y1), (x2, y1), ...
std::vector<Point> StepCorners(std::span<const Point> points);

/// The outline of the band between two step functions of the same xs (StepCorners of `upper`
/// left to right, then of `lower` back), to draw closed.
std::vector<Point> StepBand(std::span<const Point> upper, std::span<const Point> lower);

/// A name to write at the end of a line, in pixels.
struct EndLabel {
  Point at;  // the line's last point
  std::string text;
  Colour colour;
};

/// Writes each label left of its point, in 11 px text with a white halo: above it, else below
/// it (clear of a line that comes in level from the left), at the nearest spot that overlaps no
/// label placed before and stays in the chart's plot area (reaching at most 6 px into the top
/// margin). Labels are placed from the highest point down.
void DrawEndLabels(Canvas* canvas, const Chart& chart, std::vector<EndLabel> labels);

/// Colours for values: `palette` spread evenly over [lo, hi] (values outside take the end
/// colours); a range of one value is widened by 0.5 each side (its colour: the middle one).
class ColourScale {
 public:
  /// Throws std::invalid_argument for an empty palette or a bound that is not finite.
  ColourScale(double lo, double hi, std::vector<Colour> palette);
  Colour operator()(double v) const;
  double lo() const { return lo_; }
  double hi() const { return hi_; }

 private:
  double lo_, hi_;
  std::vector<Colour> palette_;
};

/// A vertical colour bar of `scale` in the box at `corner` (high values at the top; one row of
/// pixels per colour step), outlined in `font.colour`, with tick marks and labels (NiceTicks,
/// about 6, three significant digits) right of it and `title` above its left end.
void DrawColourBar(Canvas* canvas, const ColourScale& scale, Point corner, double width,
                   double height, const std::string& title, const Font& font);

/// Maps 2-D data into a square: one scale for both axes (distances keep their ratios), the
/// data's centre at the square's centre, y up, the longer extent filling the side less `margin`
/// on each end.
class SquareMap {
 public:
  SquareMap(std::span<const Point> data, Point corner, double side, double margin);
  Point operator()(Point data) const;

 private:
  Point centre_data_;
  Point centre_pixels_;
  double pixels_per_unit_ = 1;
};

}  // namespace rl::plot
