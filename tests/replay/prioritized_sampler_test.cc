#include "replay/prioritized_sampler.h"

#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <stdexcept>
#include <vector>

#include <gtest/gtest.h>

#include "tests/replay/sampler_draws.h"

namespace rl::replay {
namespace {

// Chi-square statistic of `hits` against `probability` (both by slot; slots of probability 0
// must have no hits).
double ChiSquare(const std::vector<int>& hits, const std::vector<double>& probability, int draws) {
  double chi2 = 0.0;
  for (size_t i = 0; i < hits.size(); ++i) {
    if (probability[i] == 0.0) {
      EXPECT_EQ(hits[i], 0) << "slot " << i;
      continue;
    }
    const double expected = probability[i] * draws;
    const double d = hits[i] - expected;
    chi2 += d * d / expected;
  }
  return chi2;
}

// Draws `draws` slots in batches of `batch` and counts them by slot.
std::vector<int> Hits(PrioritizedSampler* sampler, int64_t capacity, int draws, int batch,
                      uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::vector<SampledItem> items(static_cast<size_t>(batch));
  std::vector<int> hits(static_cast<size_t>(capacity), 0);
  for (int round = 0; round < draws / batch; ++round) {
    sampler->Sample(&rng, items);
    for (const SampledItem& item : items) ++hits[static_cast<size_t>(item.slot)];
  }
  return hits;
}

TEST(PrioritizedSamplerTest, RefusesBadArguments) {
  EXPECT_THROW(PrioritizedSampler(0, 0.6), std::invalid_argument);
  EXPECT_THROW(PrioritizedSampler(10, -0.1), std::invalid_argument);
  EXPECT_THROW(PrioritizedSampler(10, std::numeric_limits<double>::quiet_NaN()),
               std::invalid_argument);
  EXPECT_THROW(PrioritizedSampler(10, 0.6, 0.0), std::invalid_argument);
  EXPECT_THROW(PrioritizedSampler(10, 0.6, -1e-6), std::invalid_argument);
  EXPECT_NO_THROW(PrioritizedSampler(10, 0.0));
  EXPECT_NO_THROW(PrioritizedSampler(10, 2.0));
}

TEST(PrioritizedSamplerTest, StoresPriorityPlusEpsilonToTheAlpha) {
  PrioritizedSampler sampler(8, 0.5, 0.01);
  sampler.Insert(2, 3.0);
  sampler.Insert(6, 8.0);
  EXPECT_EQ(sampler.size(), 2);
  const double v2 = std::sqrt(3.01);
  const double v6 = std::sqrt(8.01);
  EXPECT_NEAR(sampler.Probability(2), v2 / (v2 + v6), 1e-12);
  EXPECT_NEAR(sampler.Probability(6), v6 / (v2 + v6), 1e-12);
  EXPECT_EQ(sampler.Probability(0), 0.0);
  EXPECT_NEAR(sampler.MinProbability(), v2 / (v2 + v6), 1e-12);
}

TEST(PrioritizedSamplerTest, DrawsInProportionToPriorityToTheAlpha) {
  // Chi-square test of 200000 draws over 10 slots of priorities 1 .. 10 (spread over a larger
  // capacity, with empty slots between). With 9 degrees of freedom, chi2 > 27.88 has
  // probability 0.001 when the draws follow p_i^alpha / sum; the seed is fixed, so the outcome
  // is deterministic. (Stratified batches only make the counts closer to expectation.)
  constexpr int64_t kCapacity = 25;
  constexpr double kAlpha = 0.7;
  constexpr int kDraws = 200000;
  PrioritizedSampler sampler(kCapacity, kAlpha, 1e-6);
  std::vector<double> probability(kCapacity, 0.0);
  double total = 0.0;
  for (int k = 0; k < 10; ++k) {
    const int64_t slot = 2 * k + 3;
    sampler.Insert(slot, k + 1.0);
    probability[static_cast<size_t>(slot)] = std::pow(k + 1.0 + 1e-6, kAlpha);
    total += probability[static_cast<size_t>(slot)];
  }
  for (double& p : probability) p /= total;

  // Every draw reports the probability it was made with.
  std::mt19937_64 rng(5);
  std::vector<SampledItem> items(64);
  sampler.Sample(&rng, items);
  for (const SampledItem& item : items) {
    EXPECT_NEAR(item.probability, probability[static_cast<size_t>(item.slot)], 1e-12);
  }

  const std::vector<int> hits = Hits(&sampler, kCapacity, kDraws, 100, 6);
  EXPECT_LT(ChiSquare(hits, probability, kDraws), 27.88);
  // Single draws (no stratification) follow the same law.
  const std::vector<int> single = Hits(&sampler, kCapacity, 50000, 1, 7);
  EXPECT_LT(ChiSquare(single, probability, 50000), 27.88);
}

TEST(PrioritizedSamplerTest, AlphaZeroIsUniform) {
  constexpr int64_t kCapacity = 20;
  constexpr int kDraws = 100000;
  PrioritizedSampler sampler(kCapacity, 0.0);
  for (int64_t slot = 0; slot < kCapacity; ++slot) {
    sampler.Insert(slot, std::pow(10.0, static_cast<double>(slot % 7)));
  }
  for (int64_t slot = 0; slot < kCapacity; ++slot) {
    EXPECT_DOUBLE_EQ(sampler.Probability(slot), 1.0 / kCapacity);
  }
  EXPECT_DOUBLE_EQ(sampler.MinProbability(), 1.0 / kCapacity);
  const std::vector<double> uniform(kCapacity, 1.0 / kCapacity);
  // 19 degrees of freedom: chi2 > 43.8 has probability 0.001.
  EXPECT_LT(ChiSquare(Hits(&sampler, kCapacity, kDraws, 1, 8), uniform, kDraws), 43.8);
}

TEST(PrioritizedSamplerTest, InsertWithoutPriorityUsesTheLargestPrioritySeenSoFar) {
  // alpha = 1, so that stored values are priority + epsilon.
  constexpr double kEps = 1e-6;
  PrioritizedSampler sampler(8, 1.0, kEps);
  EXPECT_EQ(sampler.max_priority(), 1.0);
  sampler.Insert(0, 0.0);  // nothing seen yet: 1
  sampler.Update(0, 5.0);  // seen: 5
  EXPECT_EQ(sampler.max_priority(), 5.0);
  sampler.Insert(1, 0.0);  // 5
  sampler.Insert(2, 3.0);  // an explicit priority below the maximum leaves it alone
  EXPECT_EQ(sampler.max_priority(), 5.0);
  sampler.Update(2, 7.0);
  sampler.Insert(3, -1.0);                                      // 7
  sampler.Insert(4, std::numeric_limits<double>::quiet_NaN());  // 7
  sampler.Update(2, 0.5);                                       // the maximum never decreases
  sampler.Insert(5, 0.0);                                       // 7
  EXPECT_EQ(sampler.max_priority(), 7.0);

  const std::vector<double> stored = {5 + kEps, 5 + kEps, 0.5 + kEps, 7 + kEps, 7 + kEps, 7 + kEps};
  double total = 0.0;
  for (double v : stored) total += v;
  for (size_t slot = 0; slot < stored.size(); ++slot) {
    EXPECT_NEAR(sampler.Probability(static_cast<int64_t>(slot)), stored[slot] / total, 1e-12)
        << slot;
  }
  EXPECT_NEAR(sampler.MinProbability(), (0.5 + kEps) / total, 1e-12);
}

TEST(PrioritizedSamplerTest, TheFirstPrioritySeenReplacesTheInitialOneEvenWhenSmaller) {
  PrioritizedSampler sampler(4, 1.0, 1e-6);
  sampler.Insert(0, 0.25);
  EXPECT_EQ(sampler.max_priority(), 0.25);
  sampler.Insert(1, 0.0);
  EXPECT_NEAR(sampler.Probability(1), 0.5, 1e-12);
  // A priority of 0 (a TD error of 0) is not taken as the maximum.
  PrioritizedSampler zero(4, 1.0, 1e-6);
  zero.Insert(0, 0.0);
  zero.Update(0, 0.0);
  EXPECT_EQ(zero.max_priority(), 1.0);
}

TEST(PrioritizedSamplerTest, UpdateChangesTheProbabilityOfStoredSlotsOnly) {
  PrioritizedSampler sampler(6, 1.0, 1e-9);
  sampler.Insert(0, 1.0);
  sampler.Insert(1, 1.0);
  EXPECT_NEAR(sampler.Probability(0), 0.5, 1e-9);
  sampler.Update(1, 3.0);
  EXPECT_NEAR(sampler.Probability(0), 0.25, 1e-9);
  EXPECT_NEAR(sampler.Probability(1), 0.75, 1e-9);
  // An empty slot stays empty, and does not raise the maximum.
  sampler.Update(4, 100.0);
  EXPECT_EQ(sampler.size(), 2);
  EXPECT_EQ(sampler.Probability(4), 0.0);
  EXPECT_EQ(sampler.max_priority(), 3.0);
  // Negative and non-finite priorities are ignored.
  sampler.Update(1, -2.0);
  sampler.Update(1, std::numeric_limits<double>::infinity());
  sampler.Update(1, std::numeric_limits<double>::quiet_NaN());
  EXPECT_NEAR(sampler.Probability(1), 0.75, 1e-9);
  // A priority of 0 leaves epsilon^alpha: still drawable.
  sampler.Update(1, 0.0);
  EXPECT_GT(sampler.Probability(1), 0.0);
  EXPECT_LT(sampler.Probability(1), 1e-8);
}

TEST(PrioritizedSamplerTest, RemovedSlotsAreNeverDrawnUntilInsertedAgain) {
  PrioritizedSampler sampler(4, 0.6);
  for (int64_t slot = 0; slot < 3; ++slot) sampler.Insert(slot, 1.0 + static_cast<double>(slot));
  sampler.Remove(1);
  sampler.Remove(1);  // twice: no effect
  sampler.Remove(3);  // never inserted: no effect
  EXPECT_EQ(sampler.size(), 2);
  EXPECT_EQ(sampler.Probability(1), 0.0);
  const std::vector<int> hits = Hits(&sampler, 4, 2000, 50, 9);
  EXPECT_EQ(hits[1], 0);
  EXPECT_EQ(hits[0] + hits[2], 2000);
  sampler.Insert(1, 0.0);
  EXPECT_EQ(sampler.size(), 3);
  EXPECT_GT(sampler.Probability(1), 0.0);
}

TEST(PrioritizedSamplerTest, ABatchDrawsOnceFromEachEqualSegment) {
  // Four equal priorities and a batch of four: segment i is exactly slot i.
  PrioritizedSampler sampler(4, 1.0);
  for (int64_t slot = 0; slot < 4; ++slot) sampler.Insert(slot, 2.0);
  std::mt19937_64 rng(10);
  std::vector<SampledItem> items(4);
  for (int round = 0; round < 100; ++round) {
    sampler.Sample(&rng, items);
    for (size_t i = 0; i < 4; ++i) ASSERT_EQ(items[i].slot, static_cast<int64_t>(i));
  }
}

TEST(PrioritizedSamplerTest, SameSeedSameDraws) {
  PrioritizedSampler a(50, 0.6);
  PrioritizedSampler b(50, 0.6);
  for (int64_t slot = 0; slot < 50; ++slot) {
    a.Insert(slot, 0.1 * static_cast<double>(slot));
    b.Insert(slot, 0.1 * static_cast<double>(slot));
  }
  EXPECT_EQ(DrawSlots(&a, 40, /*seed=*/3), DrawSlots(&b, 40, /*seed=*/3));
}

TEST(PrioritizedSamplerTest, ReportsTheMemoryOfItsTree) {
  EXPECT_EQ(PrioritizedSampler(1000, 0.6).memory_bytes(), 32 * 1024);
  EXPECT_EQ(PrioritizedSampler(1000, 0.6).MinProbability(), 0.0);
}

}  // namespace
}  // namespace rl::replay
