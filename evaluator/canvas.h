// What the plots (plot.h) draw on: a few shapes and text in pixel coordinates (origin at the top
// left, y down). SvgCanvas (svg_canvas.h) writes them as an SVG document; a raster canvas draws
// them into an image (the evaluator's t-SNE map: raster_canvas.h).
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace rl::plot {

/// An sRGB colour.
struct Colour {
  uint8_t r = 0, g = 0, b = 0;

  /// From 0xRRGGBB.
  static constexpr Colour Hex(uint32_t rgb) {
    return {static_cast<uint8_t>(rgb >> 16), static_cast<uint8_t>(rgb >> 8),
            static_cast<uint8_t>(rgb)};
  }
  /// "#rrggbb".
  std::string ToHex() const;
  bool operator==(const Colour&) const = default;
};

/// A position in pixels.
struct Point {
  double x = 0;
  double y = 0;
};

/// How a shape is painted: its inside (fill), its outline (stroke), or both; a shape with
/// neither is not drawn. Opacities are in [0, 1].
struct Paint {
  std::optional<Colour> fill;
  double fill_opacity = 1;
  std::optional<Colour> stroke;
  double stroke_width = 1;
  double stroke_opacity = 1;
  std::vector<double> dash;  // lengths of dashes and gaps, alternating; empty: solid
  bool round_joins = false;  // round corners where segments meet
  bool crisp = false;        // no anti-aliasing (edges on whole pixels)

  /// An outline of `colour`, `width` pixels wide.
  static Paint Stroke(Colour colour, double width = 1);
  /// A fill of `colour`.
  static Paint Fill(Colour colour, double opacity = 1);
};

/// What an SVG says of a shape besides its looks: a class (for styles and tests) and a tooltip
/// (a <title> child). A raster canvas ignores both.
struct Mark {
  std::string css_class;
  std::string tooltip;
};

/// Where a text's anchor point is: at its start, middle or end (on its baseline).
enum class Anchor { kStart, kMiddle, kEnd };

struct Font {
  double size = 12;  // pixels (the em)
  Colour colour;
  Anchor anchor = Anchor::kStart;
  bool bold = false;
  int rotation = 0;            // degrees clockwise about the anchor point: 0, 90, -90 or 180
  std::optional<Colour> halo;  // an outline of this colour behind the glyphs (legible on lines)
};

/// The drawing surface. Not thread-safe.
class Canvas {
 public:
  virtual ~Canvas() = default;
  virtual int width() const = 0;
  virtual int height() const = 0;

  virtual void Line(Point from, Point to, const Paint& paint, const Mark& mark = {}) = 0;
  /// Straight segments through `points` (at least 2), open.
  virtual void Polyline(std::span<const Point> points, const Paint& paint,
                        const Mark& mark = {}) = 0;
  /// The outline through `points` (at least 2), closed back to the first when `closed`.
  virtual void Path(std::span<const Point> points, bool closed, const Paint& paint,
                    const Mark& mark = {}) = 0;
  /// An axis-aligned rectangle with its top left corner at `corner`.
  virtual void Rect(Point corner, double width, double height, const Paint& paint) = 0;
  virtual void Circle(Point centre, double radius, const Paint& paint, const Mark& mark = {}) = 0;
  /// One line of UTF-8 text with its baseline through `at`.
  virtual void Text(Point at, std::string_view text, const Font& font) = 0;
  /// The width in pixels of `text` at `size` (an estimate where the canvas does not lay out text
  /// itself, as in an SVG).
  virtual double TextWidth(std::string_view text, double size) const = 0;
};

}  // namespace rl::plot
