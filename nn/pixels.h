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

/// PixelsToMatrix with every observation shifted, the random-shift augmentation of DrQ
/// (Kostrikov et al. 2020: pad by the edge pixels, crop at a random offset). Observation j is
/// `planes` planes of height x width bytes; its output pixel (y, x) in every plane is its input
/// pixel (clamp(y + dy[j]), clamp(x + dx[j])), so the edge rows and columns repeat beyond the
/// border. All planes (the frames of a stack) move together. dy = dx = 0 gives PixelsToMatrix.
/// No allocation when `out` already has the size.
void ShiftedPixelsToMatrix(const uint8_t* pixels, int planes, int height, int width, int batch,
                           const int* dy, const int* dx, Matrix* out);

}  // namespace rl::nn
