#include "nn/pixels.h"

#include <algorithm>

#include "nn/parallel.h"

namespace rl::nn {
namespace {

// One observation of ShiftedPixelsToMatrix: `in` (planes x height x width bytes) shifted by
// (dy, dx) into `to`.
void ShiftOne(const uint8_t* in, int planes, int height, int width, int dy, int dx, float* to) {
  const int64_t plane = int64_t{height} * width;
  // Output column x reads input column clamp(x + dx): the first input column left of x = lo,
  // the run of input columns [lo + dx, hi + dx) in between (converted by PixelsToFloats), and the
  // last input column from x = hi on.
  const int lo = std::clamp(-dx, 0, width);
  const int hi = std::clamp(width - dx, lo, width);
  for (int c = 0; c < planes; ++c) {
    for (int y = 0; y < height; ++y) {
      const int64_t source_y = std::clamp(y + dy, 0, height - 1);
      const uint8_t* row = in + c * plane + source_y * width;
      float* dst = to + c * plane + int64_t{y} * width;
      std::fill(dst, dst + lo, static_cast<float>(row[0]) / 255.0f);
      if (hi > lo) PixelsToFloats(row + lo + dx, hi - lo, dst + lo);
      std::fill(dst + hi, dst + width, static_cast<float>(row[width - 1]) / 255.0f);
    }
  }
}

}  // namespace

void PixelsToFloats(const uint8_t* pixels, int64_t count, float* out) {
  // A plain loop: the compiler vectorises the conversion and the division.
  for (int64_t i = 0; i < count; ++i) out[i] = static_cast<float>(pixels[i]) / 255.0f;
}

void PixelsToMatrix(const uint8_t* pixels, int features, int batch, Matrix* out) {
  out->resize(features, batch);
  internal::ParallelForColumns(batch, int64_t{features} * batch, [&](int64_t begin, int64_t end) {
    PixelsToFloats(pixels + features * begin, features * (end - begin),
                   out->data() + features * begin);
  });
}

void ShiftedPixelsToMatrix(const uint8_t* pixels, int planes, int height, int width, int batch,
                           const int* dy, const int* dx, Matrix* out) {
  const int64_t features = int64_t{planes} * height * width;
  out->resize(features, batch);
  internal::ParallelForColumns(batch, features * batch, [&](int64_t begin, int64_t end) {
    for (int64_t j = begin; j < end; ++j) {
      ShiftOne(pixels + j * features, planes, height, width, dy[j], dx[j],
               out->data() + j * features);
    }
  });
}

}  // namespace rl::nn
