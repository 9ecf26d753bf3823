// Rendering of LunarLander with the small rasteriser of envs/raster.h. It follows the reference's
// rgb_array drawing (pygame) approximately: no anti-aliasing, outlines one pixel wide, pixels
// painted when their centre is inside a shape, and no exhaust particles (they are decoration in
// the reference and need a render mode that this env does not have).
#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include "common/check.h"
#include "envs/box2d/lunar_lander.h"
#include "envs/raster.h"
#include "envs/render_args.h"

namespace rl::envs {
namespace {

constexpr Rgb kSky{0, 0, 0};
constexpr Rgb kGround{255, 255, 255};
constexpr Rgb kBodyFill{128, 102, 230};
constexpr Rgb kBodyOutline{77, 77, 128};
constexpr Rgb kFlagPole{255, 255, 255};
constexpr Rgb kFlag{204, 204, 0};
constexpr double kFlagPoleHeight = 50;  // Pixels of the native surface.

// Draws the closed outline through `points` as one quadrilateral per edge, half_width on either
// side of the edge.
void StrokeClosed(Canvas& canvas, const std::vector<Point>& points, double half_width, Rgb color) {
  for (std::size_t k = 0; k < points.size(); ++k) {
    const Point a = points[k];
    const Point b = points[(k + 1) % points.size()];
    const double length = std::hypot(b.x - a.x, b.y - a.y);
    if (!(length > 0)) continue;
    const double nx = -(b.y - a.y) / length * half_width;
    const double ny = (b.x - a.x) / length * half_width;
    const std::array<Point, 4> band = {Point{a.x + nx, a.y + ny}, Point{b.x + nx, b.y + ny},
                                       Point{b.x - nx, b.y - ny}, Point{a.x - nx, a.y - ny}};
    canvas.FillPolygon(band, color);
  }
}

// First pixel whose centre is at or after the continuous coordinate v.
int FirstCentreAtOrAfter(double v) { return static_cast<int>(std::ceil(v - 0.5)); }

}  // namespace

void LunarLander::Render(std::vector<uint8_t>* rgb, int* width, int* height) const {
  RenderNative(*this, kViewportW, kViewportH, rgb, width, height);
}

void LunarLander::RenderSized(int width, int height, std::vector<uint8_t>* rgb) const {
  CheckRenderArgs(*this, "LunarLander", width, height, rgb);

  // The reference draws on a y-up 600x400 surface (world metres times kScale) and flips it; map
  // that surface to the output image (y down), scaling each axis.
  const double sx = width / static_cast<double>(kViewportW);
  const double sy = height / static_cast<double>(kViewportH);
  const auto to_image = [&](double px, double py) {
    return Point{px * sx, (kViewportH - py) * sy};
  };
  const auto world_to_image = [&](double x, double y) { return to_image(x * kScale, y * kScale); };
  Canvas canvas(width, height, rgb);
  canvas.Clear(kGround);

  // Sky: the polygon above each terrain segment, up to the top edge.
  for (int i = 0; i + 1 < kChunks; ++i) {
    const std::array<Point, 4> sky = {world_to_image(chunk_x_[i], smooth_y_[i]),
                                      world_to_image(chunk_x_[i + 1], smooth_y_[i + 1]),
                                      world_to_image(chunk_x_[i + 1], kH),
                                      world_to_image(chunk_x_[i], kH)};
    canvas.FillPolygon(sky, kSky);
  }

  // Lander, then legs: filled, with a darker outline about one native pixel wide.
  const double half_width = 0.5 * std::min(sx, sy);
  for (const std::vector<std::array<double, 2>>& polygon : body_polygons()) {
    std::vector<Point> points;
    points.reserve(polygon.size());
    for (const auto& v : polygon) points.push_back(world_to_image(v[0], v[1]));
    canvas.FillPolygon(points, kBodyFill);
    StrokeClosed(canvas, points, half_width, kBodyOutline);
  }

  // Flags at both ends of the pad: a one-pixel pole from the pad up kFlagPoleHeight pixels (both
  // ends included), and a triangle hanging from its top towards +x. The pole stays at least one
  // pixel wide when shrinking.
  for (const double flag_x : {kHelipadX1, kHelipadX2}) {
    const double x = flag_x * kScale;
    const double y1 = kHelipadY * kScale;
    const double y2 = y1 + kFlagPoleHeight;
    const Point bottom_left = to_image(x, y1);
    const Point top_right = to_image(x + 1, y2 + 1);
    const int col0 = FirstCentreAtOrAfter(bottom_left.x);
    const int col1 = std::max(col0 + 1, FirstCentreAtOrAfter(top_right.x));
    const int row0 = FirstCentreAtOrAfter(top_right.y);
    const int row1 = std::max(row0 + 1, FirstCentreAtOrAfter(bottom_left.y));
    canvas.FillPixelRect(col0, row0, col1, row1, kFlagPole);
    const std::array<Point, 3> flag = {to_image(x, y2), to_image(x, y2 - 10),
                                       to_image(x + 25, y2 - 5)};
    canvas.FillPolygon(flag, kFlag);
  }
}

}  // namespace rl::envs
