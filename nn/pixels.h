// Conversion of 8-bit pixel observations to network inputs.
#pragma once

#include <cstdint>

#include "nn/tensor.h"

namespace rl::nn {

/// out[i] = pixels[i] / 255 (exactly the float division, as PyTorch's x.float() / 255) for
/// i < count. Vectorised; `out` must not overlap `pixels`. O(count), no allocation.
void PixelsToFloats(const uint8_t* pixels, int64_t count, float* out);

/// Fills `out` (resized to features x batch, which does not allocate when it already has that
/// size) with `batch` observations of `features` bytes stored one after another, divided by 255:
/// observation j becomes column j. For images the bytes must already be channel-major (C x H x W,
/// see ImageShape), as a stack of frames naturally is.
void PixelsToMatrix(const uint8_t* pixels, int features, int batch, Matrix* out);

}  // namespace rl::nn
