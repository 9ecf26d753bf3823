// A minimal software rasteriser for rendering classic-control environments: filled polygons and
// ellipses on an RGB byte buffer, plus area-averaging resampling. No anti-aliasing.
//
// Coordinates are continuous image coordinates: x grows to the right, y grows downwards, and pixel
// (i, j) covers [i, i+1) x [j, j+1). A pixel is painted when its centre (i + 0.5, j + 0.5) lies
// inside the shape, so shapes that share an edge never overlap or leave gaps. Everything is
// clipped to the image; shapes with a non-finite coordinate are not drawn.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

namespace rl::envs {

/// An 8-bit RGB colour.
struct Rgb {
  uint8_t r = 0;
  uint8_t g = 0;
  uint8_t b = 0;
  friend bool operator==(const Rgb&, const Rgb&) = default;
};
inline constexpr Rgb kBlack{0, 0, 0};
inline constexpr Rgb kWhite{255, 255, 255};

/// A point in continuous image coordinates (pixels, y down).
struct Point {
  double x = 0;
  double y = 0;
};

/// Draws into a caller-owned RGB buffer (row-major, top row first, 3 bytes per pixel). The canvas
/// is a view: the buffer must outlive it.
class Canvas {
 public:
  /// Resizes *pixels to width * height * 3 bytes (contents unspecified until Clear). width and
  /// height must be positive.
  Canvas(int width, int height, std::vector<uint8_t>* pixels);

  int width() const { return width_; }
  int height() const { return height_; }

  /// Paints every pixel with `color`. O(width * height).
  void Clear(Rgb color);

  /// Paints the integer pixel rectangle [x0, x1) x [y0, y1), clipped to the image.
  void FillPixelRect(int x0, int y0, int x1, int y1, Rgb color);

  /// Fills a simple or self-intersecting polygon (even-odd rule). Fewer than 3 vertices draw
  /// nothing. O(rows covered * vertices).
  void FillPolygon(std::span<const Point> vertices, Rgb color);

  /// Fills the axis-aligned ellipse ((x-cx)/rx)^2 + ((y-cy)/ry)^2 <= 1 (a circle when rx == ry).
  /// Non-positive radii draw nothing.
  void FillEllipse(Point centre, double rx, double ry, Rgb color);

  /// Colour of pixel (x, y); both must be inside the image.
  Rgb pixel(int x, int y) const;

 private:
  // Paints columns [x0, x1) of row y; the caller has clipped all three.
  void FillSpan(int y, int x0, int x1, Rgb color);

  int width_;
  int height_;
  std::vector<uint8_t>* pixels_;
};

/// Resamples an RGB image (layout as above) to dst_width x dst_height: each output pixel is the
/// average of the source area it covers, weighted by overlap and rounded to nearest (like OpenCV's
/// INTER_AREA when shrinking). All sizes must be positive and src must hold
/// src_width * src_height * 3 bytes. Resizes *dst. O(dst pixels * covered source pixels).
void ResizeRgbArea(std::span<const uint8_t> src, int src_width, int src_height, int dst_width,
                   int dst_height, std::vector<uint8_t>* dst);

}  // namespace rl::envs
