#include "envs/raster.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <utility>

#include "common/check.h"

namespace rl::envs {
namespace {

// Converts v to an int after clamping it to [lo, hi] in double, so that huge values cannot
// overflow the conversion. v must not be NaN.
int ClampToInt(double v, int lo, int hi) {
  return static_cast<int>(std::clamp(v, static_cast<double>(lo), static_cast<double>(hi)));
}

// First pixel index whose centre is >= v, clamped to [lo, hi].
int FirstCentreAtOrAfter(double v, int lo, int hi) {
  return ClampToInt(std::ceil(v - 0.5), lo, hi);
}

}  // namespace

Canvas::Canvas(int width, int height, std::vector<uint8_t>* pixels)
    : width_(width), height_(height), pixels_(pixels) {
  RL_CHECK(pixels != nullptr) << "Canvas needs a pixel buffer";
  RL_CHECK(width > 0 && height > 0)
      << "Canvas size must be positive, got " << width << "x" << height;
  pixels_->resize(static_cast<std::size_t>(width) * static_cast<std::size_t>(height) * 3);
}

void Canvas::Clear(Rgb color) { FillPixelRect(0, 0, width_, height_, color); }

void Canvas::FillPixelRect(int x0, int y0, int x1, int y1, Rgb color) {
  x0 = std::max(x0, 0);
  y0 = std::max(y0, 0);
  x1 = std::min(x1, width_);
  y1 = std::min(y1, height_);
  for (int y = y0; y < y1; ++y) FillSpan(y, x0, x1, color);
}

void Canvas::FillPolygon(std::span<const Point> vertices, Rgb color) {
  if (vertices.size() < 3) return;
  // Bounding box; skip shapes that are not finite.
  double min_y = vertices[0].y;
  double max_y = vertices[0].y;
  for (const Point& p : vertices) {
    if (!std::isfinite(p.x) || !std::isfinite(p.y)) return;
    min_y = std::min(min_y, p.y);
    max_y = std::max(max_y, p.y);
  }
  const int row_begin = FirstCentreAtOrAfter(min_y, 0, height_);
  const int row_end = FirstCentreAtOrAfter(max_y, 0, height_);

  // For each row, intersect the horizontal line through the pixel centres with every edge. An edge
  // counts when exactly one endpoint is at or below the line (half-open rule), so a vertex lying on
  // the line is counted once and horizontal edges never. Each edge is evaluated bottom-up, so that
  // polygons sharing an edge compute bit-identical crossings whatever their winding.
  std::vector<double> crossings;
  crossings.reserve(vertices.size());
  for (int row = row_begin; row < row_end; ++row) {
    const double yc = row + 0.5;
    crossings.clear();
    for (std::size_t i = 0; i < vertices.size(); ++i) {
      Point a = vertices[i];
      Point b = vertices[(i + 1) % vertices.size()];
      if ((a.y <= yc) == (b.y <= yc)) continue;
      if (a.y > b.y) std::swap(a, b);
      const double t = (yc - a.y) / (b.y - a.y);  // In [0, 1].
      const double dx = b.x - a.x;
      // The second form cannot overflow when the difference of two huge coordinates does.
      crossings.push_back(std::isfinite(dx) ? a.x + t * dx : (1 - t) * a.x + t * b.x);
    }
    std::sort(crossings.begin(), crossings.end());
    // Even-odd rule: paint pixel centres in [crossings[k], crossings[k+1]) for even k.
    for (std::size_t k = 0; k + 1 < crossings.size(); k += 2) {
      const int x0 = FirstCentreAtOrAfter(crossings[k], 0, width_);
      const int x1 = FirstCentreAtOrAfter(crossings[k + 1], 0, width_);
      FillSpan(row, x0, x1, color);
    }
  }
}

void Canvas::FillEllipse(Point centre, double rx, double ry, Rgb color) {
  if (!std::isfinite(centre.x) || !std::isfinite(centre.y) || !std::isfinite(rx) ||
      !std::isfinite(ry) || rx <= 0 || ry <= 0) {
    return;
  }
  // Rows whose centre lies within [cy - ry, cy + ry].
  const int row_begin = FirstCentreAtOrAfter(centre.y - ry, 0, height_);
  const int row_end = ClampToInt(std::floor(centre.y + ry - 0.5) + 1, 0, height_);
  for (int row = row_begin; row < row_end; ++row) {
    const double dy = (row + 0.5 - centre.y) / ry;
    const double q = 1.0 - dy * dy;
    if (q < 0) continue;
    // Columns whose centre lies within [cx - half, cx + half].
    const double half = rx * std::sqrt(q);
    const int x0 = FirstCentreAtOrAfter(centre.x - half, 0, width_);
    const int x1 = ClampToInt(std::floor(centre.x + half - 0.5) + 1, 0, width_);
    FillSpan(row, x0, x1, color);
  }
}

Rgb Canvas::pixel(int x, int y) const {
  RL_CHECK(x >= 0 && x < width_ && y >= 0 && y < height_)
      << "pixel (" << x << ", " << y << ") outside " << width_ << "x" << height_;
  const std::size_t i = (static_cast<std::size_t>(y) * width_ + x) * 3;
  return Rgb{(*pixels_)[i], (*pixels_)[i + 1], (*pixels_)[i + 2]};
}

void Canvas::FillSpan(int y, int x0, int x1, Rgb color) {
  uint8_t* p = pixels_->data() + (static_cast<std::size_t>(y) * width_ + x0) * 3;
  for (int x = x0; x < x1; ++x, p += 3) {
    p[0] = color.r;
    p[1] = color.g;
    p[2] = color.b;
  }
}

void ResizeRgbArea(std::span<const uint8_t> src, int src_width, int src_height, int dst_width,
                   int dst_height, std::vector<uint8_t>* dst) {
  RL_CHECK(dst != nullptr) << "ResizeRgbArea needs an output buffer";
  RL_CHECK(src_width > 0 && src_height > 0 && dst_width > 0 && dst_height > 0)
      << "sizes must be positive: " << src_width << "x" << src_height << " -> " << dst_width << "x"
      << dst_height;
  RL_CHECK(src.size() == static_cast<std::size_t>(src_width) * src_height * 3)
      << "source holds " << src.size() << " bytes, expected " << src_width << "x" << src_height
      << "x3";
  dst->resize(static_cast<std::size_t>(dst_width) * dst_height * 3);

  // Per axis, output pixel d covers source interval [d * s / n, (d + 1) * s / n). Precompute the
  // overlapping source indices and their overlap lengths.
  struct Tap {
    int index;
    double weight;
  };
  const auto make_taps = [](int src_n, int dst_n) {
    std::vector<std::vector<Tap>> taps(dst_n);
    const double ratio = static_cast<double>(src_n) / dst_n;
    for (int d = 0; d < dst_n; ++d) {
      const double lo = d * ratio;
      const double hi = (d + 1) * ratio;
      const int first = static_cast<int>(std::floor(lo));
      const int last = std::min(static_cast<int>(std::ceil(hi)), src_n);
      for (int s = first; s < last; ++s) {
        const double w = std::min(hi, s + 1.0) - std::max(lo, static_cast<double>(s));
        if (w > 0) taps[d].push_back(Tap{s, w});
      }
    }
    return taps;
  };
  const std::vector<std::vector<Tap>> x_taps = make_taps(src_width, dst_width);
  const std::vector<std::vector<Tap>> y_taps = make_taps(src_height, dst_height);

  // Weighted average of the covered source pixels, per channel.
  for (int dy = 0; dy < dst_height; ++dy) {
    for (int dx = 0; dx < dst_width; ++dx) {
      double sum[3] = {0, 0, 0};
      double total = 0;
      for (const Tap& ty : y_taps[dy]) {
        for (const Tap& tx : x_taps[dx]) {
          const double w = ty.weight * tx.weight;
          const std::size_t i = (static_cast<std::size_t>(ty.index) * src_width + tx.index) * 3;
          for (int c = 0; c < 3; ++c) sum[c] += w * src[i + c];
          total += w;
        }
      }
      uint8_t* out = dst->data() + (static_cast<std::size_t>(dy) * dst_width + dx) * 3;
      for (int c = 0; c < 3; ++c) {
        out[c] = static_cast<uint8_t>(std::clamp(std::lround(sum[c] / total), 0L, 255L));
      }
    }
  }
}

}  // namespace rl::envs
