#include "evaluator/raster_canvas.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <opencv2/imgproc.hpp>

namespace rl::evaluator {
namespace {

cv::Point Pixel(plot::Point p) {
  return {static_cast<int>(std::lround(p.x)), static_cast<int>(std::lround(p.y))};
}

cv::Scalar Bgr(plot::Colour c) {
  return {static_cast<double>(c.b), static_cast<double>(c.g), static_cast<double>(c.r)};
}

int LineType(const plot::Paint& paint) { return paint.crisp ? cv::LINE_8 : cv::LINE_AA; }

int Thickness(const plot::Paint& paint) {
  return std::max(1, static_cast<int>(std::lround(paint.stroke_width)));
}

// Draws with `draw` into `image`, blended in at `opacity`.
void Blend(cv::Mat* image, double opacity, const std::function<void(cv::Mat&)>& draw) {
  if (opacity >= 1) {
    draw(*image);
    return;
  }
  cv::Mat over = image->clone();
  draw(over);
  cv::addWeighted(over, opacity, *image, 1 - opacity, 0, *image);
}

// The dashes along the segments through `points`: the `dash` pattern of on and off lengths,
// continued from one segment to the next.
std::vector<std::pair<plot::Point, plot::Point>> Dashes(const std::vector<plot::Point>& points,
                                                        const std::vector<double>& dash) {
  std::vector<std::pair<plot::Point, plot::Point>> on;
  size_t k = 0;                              // the pattern's entry
  double left = dash.empty() ? 0 : dash[0];  // of it
  for (size_t i = 1; i < points.size(); ++i) {
    const plot::Point a = points[i - 1], b = points[i];
    const double length = std::hypot(b.x - a.x, b.y - a.y);
    for (double done = 0; done < length && left > 0;) {
      const double step = std::min(left, length - done);
      const auto at = [&](double d) {
        return plot::Point{a.x + (b.x - a.x) * d / length, a.y + (b.y - a.y) * d / length};
      };
      if (k % 2 == 0) on.emplace_back(at(done), at(done + step));
      done += step;
      left -= step;
      if (left <= 0) {
        k = (k + 1) % dash.size();
        left = dash[k];
      }
    }
  }
  return on;
}

}  // namespace

RasterCanvas::RasterCanvas(int width, int height)
    : image_(height, width, CV_8UC3, cv::Scalar(255, 255, 255)) {}

void RasterCanvas::Line(plot::Point from, plot::Point to, const plot::Paint& paint,
                        const plot::Mark& mark) {
  if (!paint.dash.empty() || !paint.stroke) {
    const plot::Point points[] = {from, to};
    Path(points, false, paint, mark);
    return;
  }
  Blend(&image_, paint.stroke_opacity, [&](cv::Mat& m) {
    cv::line(m, Pixel(from), Pixel(to), Bgr(*paint.stroke), Thickness(paint), LineType(paint));
  });
}

void RasterCanvas::Polyline(std::span<const plot::Point> points, const plot::Paint& paint,
                            const plot::Mark& mark) {
  Path(points, false, paint, mark);
}

void RasterCanvas::Path(std::span<const plot::Point> points, bool closed, const plot::Paint& paint,
                        const plot::Mark&) {
  std::vector<cv::Point> pixels;
  for (const plot::Point& p : points) pixels.push_back(Pixel(p));
  if (pixels.size() < 2) return;
  if (paint.fill) {
    Blend(&image_, paint.fill_opacity, [&](cv::Mat& m) {
      cv::fillPoly(m, std::vector<std::vector<cv::Point>>{pixels}, Bgr(*paint.fill),
                   LineType(paint));
    });
  }
  if (!paint.stroke) return;
  std::vector<plot::Point> outline(points.begin(), points.end());
  if (closed) outline.push_back(points.front());
  Blend(&image_, paint.stroke_opacity, [&](cv::Mat& m) {
    if (paint.dash.empty()) {
      cv::polylines(m, std::vector<std::vector<cv::Point>>{pixels}, closed, Bgr(*paint.stroke),
                    Thickness(paint), LineType(paint));
      return;
    }
    for (const auto& [a, b] : Dashes(outline, paint.dash)) {
      cv::line(m, Pixel(a), Pixel(b), Bgr(*paint.stroke), Thickness(paint), LineType(paint));
    }
  });
}

void RasterCanvas::Rect(plot::Point corner, double width, double height, const plot::Paint& paint) {
  const cv::Rect box(Pixel(corner), cv::Size(static_cast<int>(std::lround(width)),
                                             static_cast<int>(std::lround(height))));
  if (paint.fill) {
    Blend(&image_, paint.fill_opacity,
          [&](cv::Mat& m) { cv::rectangle(m, box, Bgr(*paint.fill), cv::FILLED); });
  }
  if (paint.stroke) {
    Blend(&image_, paint.stroke_opacity, [&](cv::Mat& m) {
      cv::rectangle(m, box, Bgr(*paint.stroke), Thickness(paint), LineType(paint));
    });
  }
}

void RasterCanvas::Circle(plot::Point centre, double radius, const plot::Paint& paint,
                          const plot::Mark&) {
  const int r = static_cast<int>(std::lround(radius));
  if (paint.fill) {
    Blend(&image_, paint.fill_opacity, [&](cv::Mat& m) {
      cv::circle(m, Pixel(centre), r, Bgr(*paint.fill), cv::FILLED, LineType(paint));
    });
  }
  if (paint.stroke) {
    Blend(&image_, paint.stroke_opacity, [&](cv::Mat& m) {
      cv::circle(m, Pixel(centre), r, Bgr(*paint.stroke), Thickness(paint), LineType(paint));
    });
  }
}

void RasterCanvas::Text(plot::Point at, std::string_view text, const plot::Font& font) {
  if (font.rotation != 0) throw std::invalid_argument("a raster canvas writes level text only");
  const std::string s(text);
  const double scale = font.size / kPixelsPerScale;
  const int thickness = font.bold ? 2 : 1;
  cv::Point origin = Pixel(at);
  if (font.anchor != plot::Anchor::kStart) {
    const int width = static_cast<int>(std::lround(TextWidth(text, font.size)));
    origin.x -= font.anchor == plot::Anchor::kMiddle ? width / 2 : width;
  }
  if (font.halo) {
    cv::putText(image_, s, origin, cv::FONT_HERSHEY_SIMPLEX, scale, Bgr(*font.halo), thickness + 2,
                cv::LINE_AA);
  }
  cv::putText(image_, s, origin, cv::FONT_HERSHEY_SIMPLEX, scale, Bgr(font.colour), thickness,
              cv::LINE_AA);
}

double RasterCanvas::TextWidth(std::string_view text, double size) const {
  int baseline = 0;
  return cv::getTextSize(std::string(text), cv::FONT_HERSHEY_SIMPLEX, size / kPixelsPerScale, 1,
                         &baseline)
      .width;
}

}  // namespace rl::evaluator
