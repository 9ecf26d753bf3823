// CarRacing's pictures (environments.md 3.10), drawn by point sampling on a grid of
// supersample x supersample samples per output pixel and averaging.
//
// Each sample holds a palette index (one byte), so painting a shape is a memset per scanline and
// the per-call palette has a handful of entries (black, playfield, grass, the road shades, kerbs,
// the car, the indicators). Shapes are painted in the reference's order; the last shape covering
// a sample's centre gives its colour. Differences from the reference that stay below a tenth of an
// output pixel at 96 x 96 are ignored: the 1-pixel anti-aliased outline of the road layer's
// polygons, pygame's rounding of vertices to whole surface pixels and its inclusive polygon edges.
#include "envs/box2d/car_racing_render.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdio>
#include <cstring>
#include <stdexcept>
#include <string>
#include <utility>

#include "common/check.h"

namespace rl::envs {
namespace {

constexpr double kSurfaceW = CarRacingScene::kSurfaceWidth;
constexpr double kSurfaceH = CarRacingScene::kSurfaceHeight;
constexpr double kPlayfield = CarRacingTrack::kPlayfield;
constexpr double kGrassDim = kPlayfield / 20;
constexpr int kMaxSupersample = 8;
constexpr int kMaxSamplesPerAxis = 1 << 15;  // Keeps sample indices far from int overflow.

// The indicator bar (environments.md 3.10 step 6), in surface pixels, y down.
constexpr double kSlot = kSurfaceW / 40;           // s = 25.
constexpr double kUnit = kSurfaceH / 40;           // h = 20.
constexpr double kBarTop = kSurfaceH - 5 * kUnit;  // 700.
// The reference skips an indicator whose quantity (not its length) is at most this.
constexpr double kIndicatorMin = 1e-4;
constexpr Rgb kSpeedColor{255, 255, 255};
constexpr Rgb kFrontWheelColor{0, 0, 255};
constexpr Rgb kRearWheelColor{51, 0, 255};
constexpr Rgb kSteeringColor{0, 255, 0};
constexpr Rgb kGyroColor{255, 0, 0};

// The score text. The reference renders it with pygame's freesansbold at 42 px, white on a black
// box, centred at (60, 750). This approximates that font with seven-segment digits of the same
// size: the ink of a digit is 20 x 30 px with 6 px strokes on a 23 px advance, the baseline at 765;
// '-' (the hyphen) is a 10 x 5 px bar on a 14 px advance. At 96 x 96 the text is about 9 x 3
// pixels, so only its rough shape matters.
constexpr double kTextCentreX = 60;
constexpr double kTextCentreY = kSurfaceH - kSurfaceH * 2.5 / 40;  // 750.
constexpr double kTextBoxHalfHeight = 23;  // The font's line height is about 46 px.
constexpr double kDigitAdvance = 23;
constexpr double kDigitInkLeft = 1.5;
constexpr double kDigitInkWidth = 20;
constexpr double kDigitInkHeight = 30;
constexpr double kStroke = 6;
constexpr double kBaseline = kTextCentreY + kDigitInkHeight / 2;  // 765.
constexpr double kMinusAdvance = 14;
constexpr double kMinusLeft = 2;
constexpr double kMinusWidth = 10;
constexpr double kMinusTop = kBaseline - 15;
constexpr double kMinusHeight = 5;
// Segments a to g (top, upper right, lower right, bottom, lower left, upper left, middle) lit for
// each digit, bit k for segment 'a' + k.
constexpr std::array<uint8_t, 10> kDigitSegments = {0x3f, 0x06, 0x5b, 0x4f, 0x66,
                                                    0x6d, 0x7d, 0x07, 0x7f, 0x6f};

// Writes the score as "{:04.0f}" into buf (C's %04.0f rounds the exact binary value to nearest,
// ties to even, as Python's format does) and returns the length written, at most N - 1.
template <std::size_t N>
int FormatScore(double score, char (&buf)[N]) {
  const int n = std::snprintf(buf, N, "%04.0f", score);
  return std::clamp(n, 0, static_cast<int>(N) - 1);
}

// First sample index whose centre (index + 0.5) is at or after v, clamped to [lo, hi]; lo >= 0.
// NaN gives lo, so a degenerate crossing can never index outside the grid.
int CentreAtOrAfter(double v, int lo, int hi) {
  const double c = v - 0.5;
  if (!(c > lo)) return lo;
  if (!(c < hi)) return hi;
  const int i = static_cast<int>(c);  // c > lo >= 0, so truncation is floor.
  return i + (i < c ? 1 : 0);
}

struct GridPoint {
  double x = 0;
  double y = 0;
};

// The colours of one picture. Index 0 is black.
class Palette {
 public:
  Palette() { Clear(); }

  void Clear() {
    size_ = 1;
    colors_[0] = kBlack;
    cached_color_ = kBlack;
    cached_index_ = 0;
  }

  // The index of `color`, added if new. A 257th distinct colour (more than any scene has) maps to
  // the nearest existing one.
  uint8_t Index(Rgb color) {
    if (color == cached_color_) return cached_index_;
    int found = -1;
    for (int i = 0; i < size_; ++i) {
      if (colors_[i] == color) {
        found = i;
        break;
      }
    }
    if (found < 0 && size_ < kCapacity) {
      found = size_++;
      colors_[found] = color;
    }
    if (found < 0) {
      int best = 0;
      for (int i = 0; i < size_; ++i) {
        if (Distance(colors_[i], color) < Distance(colors_[best], color)) best = i;
      }
      found = best;
    }
    cached_color_ = color;
    cached_index_ = static_cast<uint8_t>(found);
    return cached_index_;
  }

  // Colour i packed as r | g << 21 | b << 42, so that one 64-bit add sums all three channels of
  // up to 8192 samples without carries between them.
  void Pack(std::array<uint64_t, 256>* packed) const {
    for (int i = 0; i < size_; ++i) {
      (*packed)[i] =
          uint64_t{colors_[i].r} | uint64_t{colors_[i].g} << 21 | uint64_t{colors_[i].b} << 42;
    }
  }

 private:
  static constexpr int kCapacity = 256;
  static int Distance(Rgb a, Rgb b) {
    const int dr = a.r - b.r;
    const int dg = a.g - b.g;
    const int db = a.b - b.b;
    return dr * dr + dg * dg + db * db;
  }

  std::array<Rgb, kCapacity> colors_;
  int size_ = 1;
  Rgb cached_color_;
  uint8_t cached_index_ = 0;
};

// The sample grid: one palette index per sample, row-major. Sample (x, y) has its centre at
// (x + 0.5, y + 0.5) in grid coordinates.
class SampleGrid {
 public:
  SampleGrid(uint8_t* data, int width, int height) : data_(data), width_(width), height_(height) {}

  int width() const { return width_; }

  void FillRows(int row_begin, int row_end, uint8_t index) {
    row_begin = std::clamp(row_begin, 0, height_);
    row_end = std::clamp(row_end, row_begin, height_);
    std::memset(data_ + static_cast<std::size_t>(row_begin) * width_, index,
                static_cast<std::size_t>(row_end - row_begin) * width_);
  }

  // Paints the samples whose centre lies in the polygon (even-odd rule; the half-open rule of
  // envs/raster.h, so polygons sharing an edge neither overlap nor leave gaps), only in rows
  // [0, row_limit). Returns without painting when no sample can be covered, before consulting
  // `index`, which is only called for polygons that show. n <= 8.
  template <typename IndexFn>
  void FillPolygon(const GridPoint* v, int n, int row_limit, IndexFn&& index) {
    if (n < 3) return;
    double min_x = v[0].x, max_x = v[0].x, min_y = v[0].y, max_y = v[0].y;
    for (int i = 0; i < n; ++i) {
      if (!std::isfinite(v[i].x) || !std::isfinite(v[i].y)) return;
      min_x = std::min(min_x, v[i].x);
      max_x = std::max(max_x, v[i].x);
      min_y = std::min(min_y, v[i].y);
      max_y = std::max(max_y, v[i].y);
    }
    const int limit = std::min(row_limit, height_);
    const int row_begin = CentreAtOrAfter(min_y, 0, limit);
    const int row_end = CentreAtOrAfter(max_y, 0, limit);
    if (row_begin >= row_end) return;
    if (CentreAtOrAfter(min_x, 0, width_) >= CentreAtOrAfter(max_x, 0, width_)) return;
    const uint8_t color = index();

    // Each non-horizontal edge from its upper end (smaller y) down, so that two polygons sharing
    // an edge compute bit-identical crossings whatever their winding.
    struct Edge {
      double y0, y1, x0, slope;
    };
    std::array<Edge, 8> edges;
    int edge_count = 0;
    for (int i = 0; i < n; ++i) {
      GridPoint a = v[i];
      GridPoint b = v[i + 1 == n ? 0 : i + 1];
      if (a.y == b.y) continue;
      if (a.y > b.y) std::swap(a, b);
      edges[edge_count++] = Edge{a.y, b.y, a.x, (b.x - a.x) / (b.y - a.y)};
    }

    std::array<double, 8> crossings;
    for (int row = row_begin; row < row_end; ++row) {
      const double yc = row + 0.5;
      int count = 0;
      for (int e = 0; e < edge_count; ++e) {
        const Edge& edge = edges[e];
        if (edge.y0 <= yc && yc < edge.y1) {
          const double x = edge.x0 + (yc - edge.y0) * edge.slope;
          // Insertion sort: at most 8 crossings.
          int k = count++;
          while (k > 0 && crossings[k - 1] > x) {
            crossings[k] = crossings[k - 1];
            --k;
          }
          crossings[k] = x;
        }
      }
      uint8_t* line = data_ + static_cast<std::size_t>(row) * width_;
      for (int k = 0; k + 1 < count; k += 2) {
        const int x0 = CentreAtOrAfter(crossings[k], 0, width_);
        const int x1 = CentreAtOrAfter(crossings[k + 1], 0, width_);
        if (x0 < x1) std::memset(line + x0, color, static_cast<std::size_t>(x1 - x0));
      }
    }
  }

  // Paints the samples whose centre lies in [x0, x1) x [y0, y1) (corners in either order).
  void FillRect(double x0, double y0, double x1, double y1, uint8_t index) {
    if (std::isnan(x0) || std::isnan(y0) || std::isnan(x1) || std::isnan(y1)) return;
    if (x1 < x0) std::swap(x0, x1);
    if (y1 < y0) std::swap(y0, y1);
    const int c0 = CentreAtOrAfter(x0, 0, width_);
    const int c1 = CentreAtOrAfter(x1, 0, width_);
    const int r0 = CentreAtOrAfter(y0, 0, height_);
    const int r1 = CentreAtOrAfter(y1, 0, height_);
    if (c0 >= c1) return;
    for (int row = r0; row < r1; ++row) {
      std::memset(data_ + static_cast<std::size_t>(row) * width_ + c0, index,
                  static_cast<std::size_t>(c1 - c0));
    }
  }

 private:
  uint8_t* data_;
  int width_;
  int height_;
};

// World (y up) to grid coordinates (y down): the camera of CarRacingSurfacePoint followed by the
// surface-to-grid scaling, as one affine map.
struct WorldToGrid {
  double m00, m01, m02, m10, m11, m12;

  GridPoint operator()(Vec2d p) const {
    return GridPoint{m00 * p.x + m01 * p.y + m02, m10 * p.x + m11 * p.y + m12};
  }
};

WorldToGrid MakeWorldToGrid(const CarRacingScene& scene, double kx, double ky) {
  const double zoom = CarRacingZoom(scene.t);
  const double angle = -scene.hull_angle;
  const double c = std::cos(angle);
  const double s = std::sin(angle);
  const double hx = scene.hull_position.x;
  const double hy = scene.hull_position.y;
  // Surface x = 500 + zoom * (c dx - s dy), flipped y = 600 - zoom * (s dx + c dy), d = p - hull.
  return WorldToGrid{kx * zoom * c,  -kx * zoom * s, kx * (500 - zoom * (c * hx - s * hy)),
                     -ky * zoom * s, -ky * zoom * c, ky * (600 + zoom * (s * hx + c * hy))};
}

// Paints the playfield: the surface starts black and the playfield square is drawn on it. When
// the square holds the whole visible grid (it is convex, so holding its corners is enough) a clear
// does it. Only rows above bar_row (the indicator bar covers the rest).
void DrawPlayfield(const CarRacingScene& scene, const WorldToGrid& to_grid, int bar_row,
                   Palette& palette, SampleGrid& grid) {
  const int grid_width = grid.width();
  const uint8_t background = palette.Index(scene.background);
  const std::array<GridPoint, 4> square = {
      to_grid({-kPlayfield, -kPlayfield}), to_grid({kPlayfield, -kPlayfield}),
      to_grid({kPlayfield, kPlayfield}), to_grid({-kPlayfield, kPlayfield})};
  bool holds_view = false;
  const double det = to_grid.m00 * to_grid.m11 - to_grid.m01 * to_grid.m10;
  if (std::isfinite(det) && det != 0) {
    holds_view = true;
    for (const GridPoint g :
         {GridPoint{0, 0}, GridPoint{1.0 * grid_width, 0}, GridPoint{0, 1.0 * bar_row},
          GridPoint{1.0 * grid_width, 1.0 * bar_row}}) {
      const double dx = g.x - to_grid.m02;
      const double dy = g.y - to_grid.m12;
      const double wx = (to_grid.m11 * dx - to_grid.m01 * dy) / det;
      const double wy = (-to_grid.m10 * dx + to_grid.m00 * dy) / det;
      if (!(std::abs(wx) < kPlayfield && std::abs(wy) < kPlayfield)) holds_view = false;
    }
  }
  if (holds_view) {
    grid.FillRows(0, bar_row, background);
  } else {
    grid.FillRows(0, bar_row, 0);
    grid.FillPolygon(square.data(), 4, bar_row, [&] { return background; });
  }
}

// Paints the grass lattice: only the cells within reach of the view. Every visible surface point
// is within |(1000, 700) - (500, 600)| < 782 surface pixels of the hull, i.e. 782 / zoom world
// units.
void DrawGrass(const CarRacingScene& scene, const WorldToGrid& to_grid, int bar_row,
               Palette& palette, SampleGrid& grid) {
  const double zoom = CarRacingZoom(scene.t);
  const double reach = 782 / std::abs(zoom);
  int first = -20;
  int last_x = 18;
  int first_y = -20;
  int last_y = 18;
  if (std::isfinite(reach) && std::isfinite(scene.hull_position.x) &&
      std::isfinite(scene.hull_position.y)) {
    const auto cell_at = [](double w) {
      return static_cast<int>(std::clamp(std::floor(w / kGrassDim), -30.0, 30.0));
    };
    first = cell_at(scene.hull_position.x - reach);
    last_x = cell_at(scene.hull_position.x + reach);
    first_y = cell_at(scene.hull_position.y - reach);
    last_y = cell_at(scene.hull_position.y + reach);
  }
  const auto even_at_or_after = [](int k) { return k % 2 == 0 ? k : k + 1; };
  const int x_begin = std::max(-20, even_at_or_after(first));
  const int y_begin = std::max(-20, even_at_or_after(first_y));
  const int x_end = std::min(18, last_x);
  const int y_end = std::min(18, last_y);
  auto grass_index = [&] { return palette.Index(scene.grass); };
  for (int gx = x_begin; gx <= x_end; gx += 2) {
    for (int gy = y_begin; gy <= y_end; gy += 2) {
      const double x0 = kGrassDim * gx;
      const double x1 = kGrassDim * (gx + 1);
      const double y0 = kGrassDim * gy;
      const double y1 = kGrassDim * (gy + 1);
      const std::array<GridPoint, 4> cell = {to_grid({x0, y0}), to_grid({x1, y0}),
                                             to_grid({x1, y1}), to_grid({x0, y1})};
      grid.FillPolygon(cell.data(), 4, bar_row, grass_index);
    }
  }
}

// Paints axis-aligned rectangles given in surface pixels (y down) on the grid.
struct BarPainter {
  SampleGrid& grid;
  Palette& palette;
  double kx;
  double ky;

  void Rect(double x0, double y0, double x1, double y1, Rgb color) const {
    grid.FillRect(x0 * kx, y0 * ky, x1 * kx, y1 * ky, palette.Index(color));
  }
};

// The indicators of the bar: speed, the four wheel speeds, steering and gyro. The reference tests
// the raw quantity against 1e-4, not the bar length.
void DrawIndicators(const CarRacingScene& scene, const BarPainter& bar) {
  const auto vertical = [&](int slot, double quantity, double value, Rgb color) {
    if (!(std::abs(quantity) > kIndicatorMin)) return;
    bar.Rect(slot * kSlot, kSurfaceH - kUnit - kUnit * value, (slot + 1) * kSlot, kSurfaceH - kUnit,
             color);
  };
  const auto horizontal = [&](int slot, double quantity, double value, Rgb color) {
    if (!(std::abs(quantity) > kIndicatorMin)) return;
    bar.Rect(slot * kSlot, kSurfaceH - 4 * kUnit, (slot + value) * kSlot, kSurfaceH - 2 * kUnit,
             color);
  };
  vertical(5, scene.true_speed, 0.02 * scene.true_speed, kSpeedColor);
  vertical(7, scene.wheel_omega[0], 0.01 * scene.wheel_omega[0], kFrontWheelColor);
  vertical(8, scene.wheel_omega[1], 0.01 * scene.wheel_omega[1], kFrontWheelColor);
  vertical(9, scene.wheel_omega[2], 0.01 * scene.wheel_omega[2], kRearWheelColor);
  vertical(10, scene.wheel_omega[3], 0.01 * scene.wheel_omega[3], kRearWheelColor);
  horizontal(20, scene.front_joint_angle, -10.0 * scene.front_joint_angle, kSteeringColor);
  horizontal(30, scene.hull_angular_velocity, -0.8 * scene.hull_angular_velocity, kGyroColor);
}

// The score: its black box (which hides an indicator reaching that far left), then the glyphs.
void DrawScore(double score, const BarPainter& bar) {
  char text[64];
  const int length = FormatScore(score, text);
  double text_width = 0;
  for (int k = 0; k < length; ++k) text_width += text[k] == '-' ? kMinusAdvance : kDigitAdvance;
  double x = kTextCentreX - text_width / 2;
  bar.Rect(x, kTextCentreY - kTextBoxHalfHeight, x + text_width, kTextCentreY + kTextBoxHalfHeight,
           kBlack);
  const double top = kBaseline - kDigitInkHeight;
  const double mid = top + (kDigitInkHeight - kStroke) / 2;
  for (int k = 0; k < length; ++k) {
    const char ch = text[k];
    if (ch == '-') {
      bar.Rect(x + kMinusLeft, kMinusTop, x + kMinusLeft + kMinusWidth, kMinusTop + kMinusHeight,
               kWhite);
      x += kMinusAdvance;
      continue;
    }
    if (ch >= '0' && ch <= '9') {
      const uint8_t lit = kDigitSegments[ch - '0'];
      const double l = x + kDigitInkLeft;
      const double r = l + kDigitInkWidth;
      const double yb = kBaseline;
      const double ym = top + kDigitInkHeight / 2;
      if (lit & 0x01) bar.Rect(l, top, r, top + kStroke, kWhite);  // a
      if (lit & 0x02) bar.Rect(r - kStroke, top, r, ym, kWhite);   // b
      if (lit & 0x04) bar.Rect(r - kStroke, ym, r, yb, kWhite);    // c
      if (lit & 0x08) bar.Rect(l, yb - kStroke, r, yb, kWhite);    // d
      if (lit & 0x10) bar.Rect(l, ym, l + kStroke, yb, kWhite);    // e
      if (lit & 0x20) bar.Rect(l, top, l + kStroke, ym, kWhite);   // f
      if (lit & 0x40) bar.Rect(l, mid, r, mid + kStroke, kWhite);  // g
    }
    x += kDigitAdvance;  // Other characters ("nan", "inf") are not drawn.
  }
}

// Output pixel (i, j) = rounded mean of the colours of its SS x SS samples.
template <int SS>
void Resolve(const uint8_t* grid, int grid_width, int width, int height,
             const std::array<uint64_t, 256>& packed, uint8_t* out) {
  constexpr uint64_t kN = SS * SS;
  constexpr uint64_t kMask = (uint64_t{1} << 21) - 1;
  static_assert(SS >= 1 && SS <= 8, "a row of samples must fit in 64 bits");
  constexpr uint64_t kOnes = ~uint64_t{0} / 0xff >> (64 - 8 * SS);  // 0x01 in each of SS bytes.
  for (int j = 0; j < height; ++j) {
    const uint8_t* band = grid + static_cast<std::size_t>(j) * SS * grid_width;
    for (int i = 0; i < width; ++i, out += 3) {
      const uint8_t* cell = band + i * SS;
      // Most pixels lie inside one shape: compare each row of samples with the first sample as
      // one word.
      const uint8_t first = cell[0];
      const uint64_t broadcast = first * kOnes;
      uint64_t diff = 0;
      for (int r = 0; r < SS; ++r) {
        uint64_t row = 0;
        std::memcpy(&row, cell + r * grid_width, SS);
        diff |= row ^ broadcast;
      }
      if (diff == 0) {
        const uint64_t c = packed[first];
        out[0] = static_cast<uint8_t>(c);
        out[1] = static_cast<uint8_t>(c >> 21);
        out[2] = static_cast<uint8_t>(c >> 42);
        continue;
      }
      uint64_t sum = 0;
      for (int r = 0; r < SS; ++r) {
        for (int k = 0; k < SS; ++k) sum += packed[cell[r * grid_width + k]];
      }
      out[0] = static_cast<uint8_t>(((sum & kMask) + kN / 2) / kN);
      out[1] = static_cast<uint8_t>((((sum >> 21) & kMask) + kN / 2) / kN);
      out[2] = static_cast<uint8_t>((((sum >> 42) & kMask) + kN / 2) / kN);
    }
  }
}

}  // namespace

double CarRacingZoom(double t) {
  constexpr double kScale = CarRacingTrack::kScale;
  constexpr double kZoom = 2.7;
  return 0.1 * kScale * std::max(1 - t, 0.0) + kZoom * kScale * std::min(t, 1.0);
}

Vec2d CarRacingSurfacePoint(const CarRacingScene& scene, Vec2d p) {
  // The reference's order of operations: rotate, scale, add the rotated scroll, then flip.
  const double zoom = CarRacingZoom(scene.t);
  const double angle = -scene.hull_angle;
  const double c = std::cos(angle);
  const double s = std::sin(angle);
  const double scroll_x = -scene.hull_position.x * zoom;
  const double scroll_y = -scene.hull_position.y * zoom;
  const double trans_x = kSurfaceW / 2 + (scroll_x * c - scroll_y * s);
  const double trans_y = kSurfaceH / 4 + (scroll_x * s + scroll_y * c);
  const double x = (p.x * c - p.y * s) * zoom + trans_x;
  const double y = (p.x * s + p.y * c) * zoom + trans_y;
  return Vec2d{x, kSurfaceH - y};
}

std::string CarRacingScoreText(double score) {
  char buf[64];
  const int n = FormatScore(score, buf);
  return std::string(buf, static_cast<std::size_t>(n));
}

void DrawCarRacing(const CarRacingScene& scene, int width, int height, int supersample,
                   std::vector<uint8_t>* rgb) {
  RL_CHECK(rgb != nullptr) << "DrawCarRacing needs an output buffer";
  if (width <= 0 || height <= 0 || supersample < 1 || supersample > kMaxSupersample ||
      width > kMaxSamplesPerAxis / supersample || height > kMaxSamplesPerAxis / supersample) {
    throw std::invalid_argument(
        "DrawCarRacing: need width, height > 0, supersample in [1, 8] and at most " +
        std::to_string(kMaxSamplesPerAxis) + " samples per axis; got " + std::to_string(width) +
        "x" + std::to_string(height) + " at supersample " + std::to_string(supersample));
  }
  const int grid_width = width * supersample;
  const int grid_height = height * supersample;
  thread_local std::vector<uint8_t> scratch;
  scratch.resize(static_cast<std::size_t>(grid_width) * grid_height);
  SampleGrid grid(scratch.data(), grid_width, grid_height);
  const double kx = grid_width / kSurfaceW;
  const double ky = grid_height / kSurfaceH;
  const WorldToGrid to_grid = MakeWorldToGrid(scene, kx, ky);

  Palette palette;
  // The world layers only show above the bar, which covers every sample from bar_row on.
  const int bar_row = CentreAtOrAfter(kBarTop * ky, 0, grid_height);

  DrawPlayfield(scene, to_grid, bar_row, palette, grid);
  DrawGrass(scene, to_grid, bar_row, palette, grid);

  // Road tiles and kerbs, then the car, each culled when it covers no sample.
  std::array<GridPoint, 8> points;
  for (const std::vector<CarRacingScene::Polygon>* layer : {&scene.road, &scene.car}) {
    for (const CarRacingScene::Polygon& polygon : *layer) {
      const int n = std::clamp(polygon.count, 0, 8);
      for (int i = 0; i < n; ++i) points[i] = to_grid(polygon.vertices[i]);
      grid.FillPolygon(points.data(), n, bar_row, [&] { return palette.Index(polygon.color); });
    }
  }

  // Indicator bar, in surface pixels (y down) scaled to the grid.
  grid.FillRows(bar_row, grid_height, 0);
  const BarPainter bar{grid, palette, kx, ky};
  DrawIndicators(scene, bar);
  DrawScore(scene.score, bar);

  // Resolve the samples into output pixels.
  std::array<uint64_t, 256> packed{};
  palette.Pack(&packed);
  rgb->resize(static_cast<std::size_t>(width) * height * 3);
  using ResolveFn =
      void (*)(const uint8_t*, int, int, int, const std::array<uint64_t, 256>&, uint8_t*);
  static constexpr std::array<ResolveFn, kMaxSupersample> kResolve = {
      &Resolve<1>, &Resolve<2>, &Resolve<3>, &Resolve<4>,
      &Resolve<5>, &Resolve<6>, &Resolve<7>, &Resolve<8>};
  kResolve[supersample - 1](scratch.data(), grid_width, width, height, packed, rgb->data());
}

}  // namespace rl::envs
