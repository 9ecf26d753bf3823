// A Canvas (canvas.h) that writes an SVG document: standalone (the report's curve files) or
// inline in an HTML page (the compare page). Self-contained: no scripts, no fetched fonts.
#pragma once

#include <string>
#include <string_view>

#include "evaluator/canvas.h"

namespace rl::plot {

/// Escapes &, <, >, " and ' for HTML and XML text and attribute values.
std::string HtmlEscape(std::string_view text);

class SvgCanvas : public Canvas {
 public:
  /// Starts a width x height document (viewBox in the same pixels) with `title` as its <title>
  /// (what a screen reader or a tooltip says), a white background, and text of `text_colour` at
  /// `font_size` pixels unless a Font says otherwise.
  SvgCanvas(int width, int height, std::string_view title, Colour text_colour,
            double font_size = 12);

  int width() const override { return width_; }
  int height() const override { return height_; }
  void Line(Point from, Point to, const Paint& paint, const Mark& mark = {}) override;
  void Polyline(std::span<const Point> points, const Paint& paint, const Mark& mark = {}) override;
  void Path(std::span<const Point> points, bool closed, const Paint& paint,
            const Mark& mark = {}) override;
  void Rect(Point corner, double width, double height, const Paint& paint) override;
  void Circle(Point centre, double radius, const Paint& paint, const Mark& mark = {}) override;
  void Text(Point at, std::string_view text, const Font& font) override;
  /// 0.54 em per character (code point): about the mean advance of a sans-serif font.
  double TextWidth(std::string_view text, double size) const override;

  /// The document: what was drawn, and the closing tag (a trailing newline). The canvas stays
  /// usable; a later call returns the later shapes too.
  std::string Document() const;

 private:
  // Writes `<tag attributes` + paint + mark's class, then `/>` or the tooltip and `</tag>`.
  void Element(const char* tag, const std::string& attributes, const Paint& paint,
               const Mark& mark);

  int width_;
  int height_;
  Colour text_colour_;
  double font_size_;
  std::string body_;
};

}  // namespace rl::plot
