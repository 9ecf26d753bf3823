#include "nn/pixels.h"

namespace rl::nn {

void PixelsToFloats(const uint8_t* pixels, int64_t count, float* out) {
  // A plain loop: the compiler vectorises the conversion and the division.
  for (int64_t i = 0; i < count; ++i) out[i] = static_cast<float>(pixels[i]) / 255.0f;
}

void PixelsToMatrix(const uint8_t* pixels, int features, int batch, Matrix* out) {
  out->resize(features, batch);
  PixelsToFloats(pixels, static_cast<int64_t>(features) * batch, out->data());
}

}  // namespace rl::nn
