#include "evaluator/svg_canvas.h"

#include "evaluator/plot.h"

namespace rl::plot {
namespace {

// A coordinate, with one decimal.
std::string Px(double v) { return FormatNumber("%.1f", v); }

// A width, opacity or size: the shortest of up to 6 significant digits.
std::string Num(double v) { return FormatNumber("%g", v); }

std::string Attr(const char* name, const std::string& value) {
  return std::string(" ") + name + "=\"" + value + "\"";
}

std::string PaintAttributes(const Paint& p) {
  std::string s = Attr("fill", p.fill ? p.fill->ToHex() : "none");
  if (p.fill && p.fill_opacity != 1) s += Attr("fill-opacity", Num(p.fill_opacity));
  if (p.stroke) {
    s += Attr("stroke", p.stroke->ToHex()) + Attr("stroke-width", Num(p.stroke_width));
    if (p.stroke_opacity != 1) s += Attr("stroke-opacity", Num(p.stroke_opacity));
    if (!p.dash.empty()) {
      std::string dash;
      for (double d : p.dash) dash += (dash.empty() ? "" : " ") + Num(d);
      s += Attr("stroke-dasharray", dash);
    }
    if (p.round_joins) s += Attr("stroke-linejoin", "round");
  }
  if (p.crisp) s += Attr("shape-rendering", "crispEdges");
  return s;
}

}  // namespace

std::string HtmlEscape(std::string_view text) {
  std::string out;
  out.reserve(text.size() + text.size() / 8);
  for (char c : text) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      case '\'':
        out += "&#39;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

SvgCanvas::SvgCanvas(int width, int height, std::string_view title, Colour text_colour,
                     double font_size)
    : width_(width), height_(height), text_colour_(text_colour), font_size_(font_size) {
  const std::string w = std::to_string(width), h = std::to_string(height);
  body_ = "<svg xmlns=\"http://www.w3.org/2000/svg\"" + Attr("width", w) + Attr("height", h) +
          Attr("viewBox", "0 0 " + w + " " + h) +
          Attr("font-family", "-apple-system, 'Segoe UI', Helvetica, Arial, sans-serif") +
          Attr("font-size", Num(font_size)) + Attr("fill", text_colour.ToHex()) +
          Attr("role", "img") + ">\n";
  body_ += "<title>" + HtmlEscape(title) + "</title>\n";
  body_ += "<rect width=\"100%\" height=\"100%\" fill=\"#ffffff\"/>\n";
}

void SvgCanvas::Element(const char* tag, const std::string& attributes, const Paint& paint,
                        const Mark& mark) {
  body_ += std::string("<") + tag;
  if (!mark.css_class.empty()) body_ += Attr("class", HtmlEscape(mark.css_class));
  body_ += attributes + PaintAttributes(paint);
  if (mark.tooltip.empty()) {
    body_ += "/>\n";
  } else {
    body_ += "><title>" + HtmlEscape(mark.tooltip) + "</title></" + tag + ">\n";
  }
}

void SvgCanvas::Line(Point from, Point to, const Paint& paint, const Mark& mark) {
  Element(
      "line",
      Attr("x1", Px(from.x)) + Attr("y1", Px(from.y)) + Attr("x2", Px(to.x)) + Attr("y2", Px(to.y)),
      paint, mark);
}

void SvgCanvas::Polyline(std::span<const Point> points, const Paint& paint, const Mark& mark) {
  std::string list;
  for (const Point& p : points) list += (list.empty() ? "" : " ") + Px(p.x) + "," + Px(p.y);
  Element("polyline", Attr("points", list), paint, mark);
}

void SvgCanvas::Path(std::span<const Point> points, bool closed, const Paint& paint,
                     const Mark& mark) {
  // Level and upright segments as H and V (step functions are mostly those).
  std::string d;
  std::string x0, y0;
  for (const Point& p : points) {
    const std::string x = Px(p.x), y = Px(p.y);
    if (d.empty()) {
      d = "M" + x + "," + y;
    } else if (y == y0) {
      d += " H" + x;
    } else if (x == x0) {
      d += " V" + y;
    } else {
      d += " L" + x + "," + y;
    }
    x0 = x;
    y0 = y;
  }
  if (closed) d += " Z";
  Element("path", Attr("d", d), paint, mark);
}

void SvgCanvas::Rect(Point corner, double width, double height, const Paint& paint) {
  Element("rect",
          Attr("x", Px(corner.x)) + Attr("y", Px(corner.y)) + Attr("width", Px(width)) +
              Attr("height", Px(height)),
          paint, {});
}

void SvgCanvas::Circle(Point centre, double radius, const Paint& paint, const Mark& mark) {
  Element("circle", Attr("cx", Px(centre.x)) + Attr("cy", Px(centre.y)) + Attr("r", Num(radius)),
          paint, mark);
}

void SvgCanvas::Text(Point at, std::string_view text, const Font& font) {
  body_ += "<text" + Attr("x", Px(at.x)) + Attr("y", Px(at.y));
  if (font.size != font_size_) body_ += Attr("font-size", Num(font.size));
  if (font.bold) body_ += Attr("font-weight", "600");
  if (!(font.colour == text_colour_)) body_ += Attr("fill", font.colour.ToHex());
  if (font.anchor != Anchor::kStart) {
    body_ += Attr("text-anchor", font.anchor == Anchor::kMiddle ? "middle" : "end");
  }
  if (font.rotation != 0) {
    body_ += Attr("transform", "rotate(" + std::to_string(font.rotation) + " " + Px(at.x) + " " +
                                   Px(at.y) + ")");
  }
  if (font.halo) {
    body_ += Attr("stroke", font.halo->ToHex()) + Attr("stroke-width", "3") +
             Attr("paint-order", "stroke") + Attr("stroke-linejoin", "round");
  }
  body_ += ">" + HtmlEscape(text) + "</text>\n";
}

double SvgCanvas::TextWidth(std::string_view text, double size) const {
  size_t characters = 0;
  for (char c : text) {
    if ((static_cast<unsigned char>(c) & 0xC0) != 0x80) ++characters;  // not a continuation byte
  }
  return 0.54 * size * static_cast<double>(characters);
}

std::string SvgCanvas::Document() const { return body_ + "</svg>\n"; }

}  // namespace rl::plot
