// Checks of rendered images: their size, the colours of given pixels, and that an env draws
// nothing before its first Reset.
#pragma once

#include <cstddef>
#include <cstdint>
#include <initializer_list>
#include <stdexcept>
#include <vector>

#include <gtest/gtest.h>

#include "envs/raster.h"
#include "tests/envs/image_testing.h"

namespace rl::envs {

// Expects `image` to be width x height pixels of 3 bytes.
inline void ExpectSize(const Image& image, int width, int height) {
  EXPECT_EQ(image.width, width);
  EXPECT_EQ(image.height, height);
  EXPECT_EQ(image.rgb.size(), static_cast<std::size_t>(width) * height * 3);
}

// A pixel (column x, row y) and the colour it must have.
struct PixelColor {
  int x;
  int y;
  Rgb color;
};

// Expects each of `pixels` to have its colour in `image`; a failure names the pixel.
inline void ExpectPixels(const Image& image, std::initializer_list<PixelColor> pixels) {
  for (const PixelColor& p : pixels) {
    EXPECT_EQ(image.at(p.x, p.y), p.color) << "pixel (" << p.x << ", " << p.y << ")";
  }
}

// Expects env.Render (any env with Render) to throw std::logic_error, as it must before the
// env's first Reset.
template <class E>
void ExpectRenderRefusedBeforeReset(E& env) {
  std::vector<uint8_t> rgb;
  int width = 0;
  int height = 0;
  EXPECT_THROW(env.Render(&rgb, &width, &height), std::logic_error);
}

}  // namespace rl::envs
