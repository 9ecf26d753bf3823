// Helpers of the rendering tests: a rendered RGB image with pixel access, an env's picture as one,
// and where the pixels of one colour are.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "envs/raster.h"

namespace rl::envs {

// A rendered RGB image (row-major, top row first, 3 bytes a pixel).
struct Image {
  std::vector<uint8_t> rgb;
  int width = 0;
  int height = 0;

  Rgb at(int x, int y) const {
    const std::size_t i = (static_cast<std::size_t>(y) * width + x) * 3;
    return Rgb{rgb[i], rgb[i + 1], rgb[i + 2]};
  }
};

// The picture of `env` (any env with Render) at its native size.
template <class E>
Image Rendered(E& env) {
  Image image;
  env.Render(&image.rgb, &image.width, &image.height);
  return image;
}

// The picture of `env` (any env with RenderSized) at width x height.
template <class E>
Image RenderedSized(E& env, int width, int height) {
  Image image;
  image.width = width;
  image.height = height;
  env.RenderSized(width, height, &image.rgb);
  return image;
}

// Count and mean position of the pixels of one colour.
struct Blob {
  int count = 0;
  double mean_x = 0;
  double mean_y = 0;
};

// The pixels of `color`, skipping row `skip_row` (-1: none).
inline Blob FindColor(const Image& image, Rgb color, int skip_row = -1) {
  Blob blob;
  for (int y = 0; y < image.height; ++y) {
    if (y == skip_row) continue;
    for (int x = 0; x < image.width; ++x) {
      if (image.at(x, y) == color) {
        ++blob.count;
        blob.mean_x += x;
        blob.mean_y += y;
      }
    }
  }
  if (blob.count > 0) {
    blob.mean_x /= blob.count;
    blob.mean_y /= blob.count;
  }
  return blob;
}

}  // namespace rl::envs
