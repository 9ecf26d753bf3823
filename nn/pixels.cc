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
    for (int c = 0; c < planes; ++c) {
      for (int y = 0; y < height; ++y) {
        const int64_t source_y = std::clamp(y + dy[j], 0, height - 1);
        const uint8_t* row = in + c * plane + source_y * width;
        float* dst = to + c * plane + int64_t{y} * width;
        for (int x = 0; x < width; ++x) {
          dst[x] = static_cast<float>(row[std::clamp(x + dx[j], 0, width - 1)]) / 255.0f;
        }
      }
    }
  }
}

}  // namespace rl::nn
