#include "envs/rng.h"

#include <algorithm>
#include <array>
#include <cstdint>
#include <random>

#include <gtest/gtest.h>

namespace rl::envs {
namespace {

TEST(RngTest, SeedingUsesBothHalvesOfTheSeed) {
  std::mt19937_64 a;
  std::mt19937_64 b;
  std::mt19937_64 c;
  SeedRng(5, a);
  SeedRng(5, b);
  SeedRng(5 + (uint64_t{1} << 32), c);
  const uint64_t first = a();
  EXPECT_EQ(first, b());
  EXPECT_NE(first, c());
}

TEST(RngTest, UniformDoubleStaysInTheHalfOpenRangeAndCoversIt) {
  std::mt19937_64 rng;
  SeedRng(1, rng);
  double lo = 1e9;
  double hi = -1e9;
  double sum = 0;
  constexpr int kDraws = 20000;
  for (int i = 0; i < kDraws; ++i) {
    const double v = UniformDouble(rng, -2.0, 6.0);
    ASSERT_GE(v, -2.0);
    ASSERT_LT(v, 6.0);
    lo = std::min(lo, v);
    hi = std::max(hi, v);
    sum += v;
  }
  EXPECT_LT(lo, -1.99);
  EXPECT_GT(hi, 5.99);
  EXPECT_NEAR(sum / kDraws, 2.0, 0.05);  // Standard error ~0.016.
}

TEST(RngTest, UniformIntExcludesTheUpperBoundAndHitsEveryValue) {
  std::mt19937_64 rng;
  SeedRng(2, rng);
  std::array<int, 7> counts{};
  for (int i = 0; i < 7000; ++i) {
    const int64_t v = UniformInt(rng, -3, 4);
    ASSERT_GE(v, -3);
    ASSERT_LT(v, 4);
    ++counts[v + 3];
  }
  for (int c : counts) EXPECT_NEAR(c, 1000, 150);
  // The LunarLander wind range, and a degenerate one-value range.
  for (int i = 0; i < 1000; ++i) {
    const int64_t v = UniformInt(rng, -9999, 9999);
    ASSERT_GE(v, -9999);
    ASSERT_LE(v, 9998);
  }
  EXPECT_EQ(UniformInt(rng, 7, 8), 7);
}

}  // namespace
}  // namespace rl::envs
