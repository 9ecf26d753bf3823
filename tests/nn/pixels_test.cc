#include "nn/pixels.h"

#include <algorithm>
#include <cstdint>
#include <vector>

#include <gtest/gtest.h>

namespace rl::nn {
namespace {

TEST(PixelsTest, DividesEveryByteValueBy255Exactly) {
  std::vector<uint8_t> bytes(256 * 3);
  for (size_t i = 0; i < bytes.size(); ++i) bytes[i] = static_cast<uint8_t>(i % 256);
  std::vector<float> out(bytes.size());
  PixelsToFloats(bytes.data(), static_cast<int64_t>(bytes.size()), out.data());
  for (size_t i = 0; i < bytes.size(); ++i) {
    EXPECT_EQ(out[i], static_cast<float>(bytes[i]) / 255.0f) << i;
  }
  EXPECT_EQ(out[255], 1.0f);
  EXPECT_EQ(out[256], 0.0f);
}

TEST(PixelsTest, PixelsToMatrixPutsOneObservationPerColumnAndReusesTheBuffer) {
  constexpr int kFeatures = 37;
  constexpr int kBatch = 5;
  std::vector<uint8_t> bytes(kFeatures * kBatch);
  for (size_t i = 0; i < bytes.size(); ++i) bytes[i] = static_cast<uint8_t>((i * 7) % 251);
  Matrix m;
  PixelsToMatrix(bytes.data(), kFeatures, kBatch, &m);
  ASSERT_EQ(m.rows(), kFeatures);
  ASSERT_EQ(m.cols(), kBatch);
  EXPECT_EQ(m(3, 2), static_cast<float>(bytes[2 * kFeatures + 3]) / 255.0f);
  const float* data = m.data();
  bytes[0] = 255;
  PixelsToMatrix(bytes.data(), kFeatures, kBatch, &m);
  EXPECT_EQ(m.data(), data);
  EXPECT_EQ(m(0, 0), 1.0f);
}

TEST(PixelsTest, AShiftOfZeroIsPixelsToMatrix) {
  constexpr int kPlanes = 2, kH = 5, kW = 7, kBatch = 3;
  std::vector<uint8_t> bytes(kPlanes * kH * kW * kBatch);
  for (size_t i = 0; i < bytes.size(); ++i) bytes[i] = static_cast<uint8_t>((i * 13) % 256);
  const std::vector<int> zero(kBatch, 0);
  Matrix plain, shifted;
  PixelsToMatrix(bytes.data(), kPlanes * kH * kW, kBatch, &plain);
  ShiftedPixelsToMatrix(bytes.data(), kPlanes, kH, kW, kBatch, zero.data(), zero.data(), &shifted);
  EXPECT_EQ(plain, shifted);
}

TEST(PixelsTest, AShiftMovesEveryPlaneOfAnObservationTogetherAndRepeatsTheEdges) {
  constexpr int kPlanes = 2, kH = 6, kW = 8, kPlane = kH * kW;
  // Observation 0: a bright dot at (3, 4) in both planes. Observation 1: column x holds x + 1.
  std::vector<uint8_t> bytes(2 * kPlanes * kPlane, 0);
  for (int c = 0; c < kPlanes; ++c) bytes[c * kPlane + 3 * kW + 4] = 200;
  for (int c = 0; c < kPlanes; ++c) {
    for (int y = 0; y < kH; ++y) {
      for (int x = 0; x < kW; ++x) bytes[(kPlanes + c) * kPlane + y * kW + x] = uint8_t(x + 1);
    }
  }
  const std::vector<int> dy = {1, 0}, dx = {-2, 3};
  Matrix m;
  ShiftedPixelsToMatrix(bytes.data(), kPlanes, kH, kW, 2, dy.data(), dx.data(), &m);
  ASSERT_EQ(m.rows(), kPlanes * kPlane);
  ASSERT_EQ(m.cols(), 2);
  // Output (y, x) reads input (y + dy, x + dx): the dot moves to (3 - 1, 4 + 2) in both planes,
  // and nothing else is lit.
  for (int c = 0; c < kPlanes; ++c) {
    for (int y = 0; y < kH; ++y) {
      for (int x = 0; x < kW; ++x) {
        const float expected = (y == 2 && x == 6) ? 200.0f / 255.0f : 0.0f;
        EXPECT_EQ(m(c * kPlane + y * kW + x, 0), expected) << c << " " << y << " " << x;
      }
    }
  }
  // Shifted left by 3: column x shows input column min(x + 3, 7); the last column repeats.
  for (int c = 0; c < kPlanes; ++c) {
    for (int x = 0; x < kW; ++x) {
      const int source = std::min(x + 3, kW - 1);
      EXPECT_EQ(m(c * kPlane + 2 * kW + x, 1), static_cast<float>(source + 1) / 255.0f) << x;
    }
  }
}

TEST(PixelsTest, EveryShiftMatchesTheClampedReadPixelByPixel) {
  // Shifts from beyond one edge to beyond the other on both axes, against output (c, y, x) =
  // input (c, clamp(y + dy), clamp(x + dx)) / 255 read pixel by pixel.
  constexpr int kPlanes = 3, kH = 7, kW = 37, kPlane = kH * kW;
  std::vector<int> dy, dx;
  for (int sy = -kH - 1; sy <= kH + 1; sy += 3) {
    for (int sx = -kW - 2; sx <= kW + 2; ++sx) {
      dy.push_back(sy);
      dx.push_back(sx);
    }
  }
  const int batch = static_cast<int>(dy.size());
  std::vector<uint8_t> bytes(static_cast<size_t>(kPlanes) * kPlane * batch);
  for (size_t i = 0; i < bytes.size(); ++i) bytes[i] = static_cast<uint8_t>((i * 97 + 13) % 256);
  Matrix m;
  ShiftedPixelsToMatrix(bytes.data(), kPlanes, kH, kW, batch, dy.data(), dx.data(), &m);
  ASSERT_EQ(m.rows(), kPlanes * kPlane);
  ASSERT_EQ(m.cols(), batch);
  for (int j = 0; j < batch; ++j) {
    for (int c = 0; c < kPlanes; ++c) {
      for (int y = 0; y < kH; ++y) {
        for (int x = 0; x < kW; ++x) {
          const int sy = std::clamp(y + dy[static_cast<size_t>(j)], 0, kH - 1);
          const int sx = std::clamp(x + dx[static_cast<size_t>(j)], 0, kW - 1);
          const uint8_t byte =
              bytes[static_cast<size_t>((j * kPlanes + c) * kPlane + sy * kW + sx)];
          ASSERT_EQ(m(c * kPlane + y * kW + x, j), static_cast<float>(byte) / 255.0f)
              << "shift (" << dy[static_cast<size_t>(j)] << ", " << dx[static_cast<size_t>(j)]
              << ") at (" << c << ", " << y << ", " << x << ")";
        }
      }
    }
  }
}

}  // namespace
}  // namespace rl::nn
