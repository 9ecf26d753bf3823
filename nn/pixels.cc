#include "nn/pixels.h"

#include <algorithm>

namespace rl::nn {

void PixelsToFloats(const uint8_t* pixels, int64_t count, float* out) {
  // A plain loop: the compiler vectorises the conversion and the division.
  for (int64_t i = 0; i < count; ++i) out[i] = static_cast<float>(pixels[i]) / 255.0f;
}

void PixelsToMatrix(const uint8_t* pixels, int features, int batch, Matrix* out) {
  out->resize(features, batch);
  PixelsToFloats(pixels, static_cast<int64_t>(features) * batch, out->data());
}

void ShiftedPixelsToMatrix(const uint8_t* pixels, int planes, int height, int width, int batch,
                           const int* dy, const int* dx, Matrix* out) {
  const int64_t plane = int64_t{height} * width;
  const int64_t features = planes * plane;
  out->resize(features, batch);
  for (int j = 0; j < batch; ++j) {
    const uint8_t* in = pixels + j * features;
    float* to = out->data() + j * features;
    // Output column x reads input column clamp(x + d): the first input column left of
    // x = lo, the run of input columns [lo + d, hi + d) in between (converted by PixelsToFloats),
    // and the last input column from x = hi on.
    const int d = dx[j];
    const int lo = std::clamp(-d, 0, width);
    const int hi = std::clamp(width - d, lo, width);
    for (int c = 0; c < planes; ++c) {
      for (int y = 0; y < height; ++y) {
        const int64_t source_y = std::clamp(y + dy[j], 0, height - 1);
        const uint8_t* row = in + c * plane + source_y * width;
        float* dst = to + c * plane + int64_t{y} * width;
        std::fill(dst, dst + lo, static_cast<float>(row[0]) / 255.0f);
        if (hi > lo) PixelsToFloats(row + lo + d, hi - lo, dst + lo);
        std::fill(dst + hi, dst + width, static_cast<float>(row[width - 1]) / 255.0f);
      }
    }
  }
}

}  // namespace rl::nn
