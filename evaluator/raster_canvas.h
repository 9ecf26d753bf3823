// A Canvas (canvas.h) that draws into an OpenCV image, for the plots the evaluator writes as PNG
// (the t-SNE map, tsne_map.h).
#pragma once

#include <opencv2/core.hpp>

#include "evaluator/canvas.h"

namespace rl::evaluator {

/// Draws with OpenCV into a BGR image (8 bits a channel) that starts white. Text is OpenCV's
/// Hershey simplex font, kPixelsPerScale pixels to the em at scale 1, level only (a Font with a
/// rotation is refused). Coordinates are rounded to whole pixels. Not thread-safe.
class RasterCanvas : public plot::Canvas {
 public:
  static constexpr double kPixelsPerScale = 30;

  RasterCanvas(int width, int height);

  /// The picture so far; the caller may draw into it too (e.g. images).
  cv::Mat& image() { return image_; }

  int width() const override { return image_.cols; }
  int height() const override { return image_.rows; }
  void Line(plot::Point from, plot::Point to, const plot::Paint& paint,
            const plot::Mark& mark = {}) override;
  void Polyline(std::span<const plot::Point> points, const plot::Paint& paint,
                const plot::Mark& mark = {}) override;
  void Path(std::span<const plot::Point> points, bool closed, const plot::Paint& paint,
            const plot::Mark& mark = {}) override;
  void Rect(plot::Point corner, double width, double height, const plot::Paint& paint) override;
  void Circle(plot::Point centre, double radius, const plot::Paint& paint,
              const plot::Mark& mark = {}) override;
  /// Throws std::invalid_argument for a rotated font.
  void Text(plot::Point at, std::string_view text, const plot::Font& font) override;
  double TextWidth(std::string_view text, double size) const override;

 private:
  cv::Mat image_;
};

}  // namespace rl::evaluator
