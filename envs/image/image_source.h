// ImageSource: the small internal interface through which the wrappers of the pixel pipeline
// (action_repeat.h -> frame_processor.h -> frame_stack.h) hand their current picture to the next
// wrapper. It is an Env like any other, plus the image of its current state.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>

#include "envs/env.h"

namespace rl::envs {

/// Shape of an 8-bit image stored packed, row-major, top row first, channels interleaved.
struct ImageShape {
  int width = 0;
  int height = 0;
  int channels = 0;  // 3 for RGB, 1 for grayscale.

  /// Number of bytes of an image of this shape.
  std::size_t bytes() const {
    return static_cast<std::size_t>(width) * static_cast<std::size_t>(height) *
           static_cast<std::size_t>(channels);
  }
  friend bool operator==(const ImageShape&, const ImageShape&) = default;
};

/// An Env that also exposes an image of its current state. Not thread-safe.
class ImageSource : public Env {
 public:
  /// Shape of every image(); fixed at construction.
  virtual ImageShape image_shape() const = 0;

  /// The current image, image_shape().bytes() bytes. Valid until the next Reset or Step. Throws
  /// std::logic_error before the first Reset.
  virtual std::span<const uint8_t> image() const = 0;

 protected:
  using Env::Env;
};

}  // namespace rl::envs
