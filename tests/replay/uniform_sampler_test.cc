#include "replay/uniform_sampler.h"

#include <cstdint>
#include <random>
#include <stdexcept>
#include <vector>

#include <gtest/gtest.h>

#include "tests/replay/sampler_draws.h"

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

TEST(UniformSamplerTest, RemovedSlotsAreNeverDrawnUntilInsertedAgain) {
  UniformSampler sampler(6);
  for (int64_t slot = 0; slot < 5; ++slot) sampler.Insert(slot, 0.0);
  sampler.Remove(2);
  sampler.Remove(2);  // twice: no effect
  sampler.Remove(5);  // never inserted: no effect
  sampler.Remove(4);  // the last one
  EXPECT_EQ(sampler.size(), 3);
  EXPECT_EQ(sampler.Probability(2), 0.0);
  EXPECT_EQ(sampler.Probability(4), 0.0);
  EXPECT_DOUBLE_EQ(sampler.Probability(0), 1.0 / 3.0);
  EXPECT_DOUBLE_EQ(sampler.MinProbability(), 1.0 / 3.0);
  std::mt19937_64 rng(4);
  std::vector<SampledItem> items(600);
  sampler.Sample(&rng, items);
  for (const SampledItem& item : items) {
    ASSERT_TRUE(item.slot == 0 || item.slot == 1 || item.slot == 3) << item.slot;
  }
  sampler.Insert(2, 0.0);
  EXPECT_EQ(sampler.size(), 4);
  EXPECT_DOUBLE_EQ(sampler.Probability(2), 0.25);
}

TEST(UniformSamplerTest, IgnoresPrioritiesAndReportsOneOverSize) {
  UniformSampler sampler(10);
  EXPECT_EQ(sampler.MinProbability(), 0.0);
  sampler.Insert(0, 100.0);
  sampler.Insert(1, 0.001);
  sampler.Update(0, 1e6);
  EXPECT_EQ(sampler.Probability(0), 0.5);
  EXPECT_EQ(sampler.Probability(1), 0.5);
  EXPECT_EQ(sampler.MinProbability(), 0.5);
  // 8 bytes of position and 8 of slot list per slot.
  EXPECT_EQ(sampler.memory_bytes(), 16 * 10);
}

TEST(UniformSamplerTest, SameSeedSameDraws) {
  UniformSampler a(10);
  UniformSampler b(10);
  for (int64_t slot = 0; slot < 10; ++slot) {
    a.Insert(slot, 0.0);
    b.Insert(slot, 0.0);
  }
  EXPECT_EQ(DrawSlots(&a, 50, /*seed=*/3), DrawSlots(&b, 50, /*seed=*/3));
}

}  // namespace
}  // namespace rl::replay
