#include "nn/pixels.h"

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

}  // namespace
}  // namespace rl::nn
