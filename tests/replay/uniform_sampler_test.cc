#include "replay/uniform_sampler.h"

#include <random>
#include <stdexcept>
#include <vector>

#include <gtest/gtest.h>

namespace rl::replay {
namespace {

TEST(UniformSamplerTest, RefusesAZeroCapacity) {
  EXPECT_THROW(UniformSampler(0), std::invalid_argument);
}

TEST(UniformSamplerTest, CountsEachSlotOnceEvenWhenReplaced) {
  UniformSampler sampler(4);
  sampler.Insert(0, 0.0);
  sampler.Insert(1, 0.0);
  sampler.Insert(1, 0.0);
  EXPECT_EQ(sampler.size(), 2);
}

TEST(UniformSamplerTest, DrawsOnlyInsertedSlotsWithProbabilityOneOverSize) {
  UniformSampler sampler(100);
  for (int64_t slot : {3, 50, 99}) sampler.Insert(slot, 0.0);
  std::mt19937_64 rng(7);
  std::vector<SampledItem> items(3000);
  sampler.Sample(&rng, items);
  std::vector<int> hits(100, 0);
  for (const SampledItem& item : items) {
    ASSERT_TRUE(item.slot == 3 || item.slot == 50 || item.slot == 99) << item.slot;
    EXPECT_DOUBLE_EQ(item.probability, 1.0 / 3.0);
    ++hits[static_cast<size_t>(item.slot)];
  }
  // Each of the three is drawn about 1000 times.
  for (int64_t slot : {3, 50, 99}) {
    EXPECT_GT(hits[static_cast<size_t>(slot)], 850);
    EXPECT_LT(hits[static_cast<size_t>(slot)], 1150);
  }
}

TEST(UniformSamplerTest, SameSeedSameDraws) {
  UniformSampler a(10);
  UniformSampler b(10);
  for (int64_t slot = 0; slot < 10; ++slot) {
    a.Insert(slot, 0.0);
    b.Insert(slot, 0.0);
  }
  std::mt19937_64 rng_a(3);
  std::mt19937_64 rng_b(3);
  std::vector<SampledItem> from_a(50);
  std::vector<SampledItem> from_b(50);
  a.Sample(&rng_a, from_a);
  b.Sample(&rng_b, from_b);
  for (size_t i = 0; i < from_a.size(); ++i) EXPECT_EQ(from_a[i].slot, from_b[i].slot);
}

}  // namespace
}  // namespace rl::replay
