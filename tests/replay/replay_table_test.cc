#include "replay/replay_table.h"

#include <cstdint>
#include <random>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

namespace rl::replay {
namespace {

// Transitions whose every field is derived from their number v, so that a sampled transition
// can be checked field by field: obs = {v, v + 0.25, ...}, next_obs = obs + 100,
// action = v % 3, reward = 2v, discount = 0.5 when v is odd else 1, episode_id = v / 10.
struct OwnedBatch {
  int obs_size = 0;
  int count = 0;
  std::vector<float> obs, next_obs, reward, discount, priority;
  std::vector<int32_t> action;
  std::vector<int64_t> episode_id;

  TransitionBatchView view() const {
    return {obs_size, count, obs, next_obs, action, reward, discount, episode_id, priority};
  }
};

OwnedBatch MakeBatch(int first, int count, int obs_size) {
  OwnedBatch b;
  b.obs_size = obs_size;
  b.count = count;
  for (int v = first; v < first + count; ++v) {
    for (int j = 0; j < obs_size; ++j) {
      b.obs.push_back(static_cast<float>(v) + 0.25f * static_cast<float>(j));
      b.next_obs.push_back(static_cast<float>(v) + 0.25f * static_cast<float>(j) + 100.0f);
    }
    b.action.push_back(v % 3);
    b.reward.push_back(2.0f * static_cast<float>(v));
    b.discount.push_back(v % 2 == 1 ? 0.5f : 1.0f);
    b.episode_id.push_back(v / 10);
    b.priority.push_back(0.0f);
  }
  return b;
}

ReplayTableOptions Options(int64_t capacity, int obs_size = 0) {
  ReplayTableOptions o;
  o.capacity = capacity;
  o.obs_size = obs_size;
  return o;
}

// Checks that sampled transition i is exactly transition number v = obs[i * obs_size].
void ExpectConsistent(const SampleBatch& s, int i) {
  const auto k = static_cast<size_t>(i);
  const auto obs_size = static_cast<size_t>(s.obs_size);
  const float v = s.obs[k * obs_size];
  const auto n = static_cast<int>(v);
  ASSERT_EQ(static_cast<float>(n), v);
  for (size_t j = 0; j < obs_size; ++j) {
    EXPECT_EQ(s.obs[k * obs_size + j], v + 0.25f * static_cast<float>(j));
    EXPECT_EQ(s.next_obs[k * obs_size + j], v + 0.25f * static_cast<float>(j) + 100.0f);
  }
  EXPECT_EQ(s.action[k], n % 3);
  EXPECT_EQ(s.reward[k], 2.0f * v);
  EXPECT_EQ(s.discount[k], n % 2 == 1 ? 0.5f : 1.0f);
  EXPECT_EQ(s.episode_id[k], n / 10);
  EXPECT_EQ(s.weight[k], 1.0f);
}

TEST(ReplayTableTest, DefaultOptionsAreValid) { EXPECT_NO_THROW(ReplayTableOptions{}.Validate()); }

TEST(ReplayTableTest, RefusesBadOptions) {
  EXPECT_THROW(ReplayTable(Options(0)), std::invalid_argument);
  EXPECT_THROW(ReplayTable(Options(10, -1)), std::invalid_argument);
}

TEST(ReplayTableTest, StoresABatchAndReportsItsSize) {
  ReplayTable table(Options(100));
  EXPECT_EQ(table.obs_size(), 0);
  ASSERT_EQ(table.Insert(MakeBatch(0, 7, 4).view()), nullptr);
  EXPECT_EQ(table.size(), 7);
  EXPECT_EQ(table.obs_size(), 4);
  EXPECT_EQ(table.total_inserts(), 7);
}

TEST(ReplayTableTest, OverwritesTheOldestWhenFull) {
  constexpr int kCapacity = 8;
  constexpr int kExtra = 3;
  ReplayTable table(Options(kCapacity));
  // Insert in uneven batches so that one batch wraps around the end.
  ASSERT_EQ(table.Insert(MakeBatch(0, 5, 2).view()), nullptr);
  ASSERT_EQ(table.Insert(MakeBatch(5, 5, 2).view()), nullptr);
  ASSERT_EQ(table.Insert(MakeBatch(10, 1, 2).view()), nullptr);
  EXPECT_EQ(table.size(), kCapacity);
  EXPECT_EQ(table.total_inserts(), kCapacity + kExtra);

  std::mt19937_64 rng(1);
  SampleBatch s;
  s.Resize(500, table.obs_size());
  ASSERT_TRUE(table.Sample(500, &rng, s.spans()));
  std::set<int> seen;
  for (int i = 0; i < 500; ++i) {
    ExpectConsistent(s, i);
    const int v = static_cast<int>(s.obs[static_cast<size_t>(i) * 2]);
    // The index is the transition's insert number.
    EXPECT_EQ(s.index[static_cast<size_t>(i)], v);
    seen.insert(v);
  }
  // The first kExtra are gone, all the others are there.
  std::set<int> expected;
  for (int v = kExtra; v < kCapacity + kExtra; ++v) expected.insert(v);
  EXPECT_EQ(seen, expected);
}

TEST(ReplayTableTest, ABatchLargerThanTheCapacityKeepsItsNewestTransitions) {
  ReplayTable table(Options(4));
  ASSERT_EQ(table.Insert(MakeBatch(0, 10, 1).view()), nullptr);
  EXPECT_EQ(table.size(), 4);
  std::mt19937_64 rng(2);
  SampleBatch s;
  s.Resize(200, 1);
  ASSERT_TRUE(table.Sample(200, &rng, s.spans()));
  std::set<float> seen(s.obs.begin(), s.obs.end());
  EXPECT_EQ(seen, (std::set<float>{6, 7, 8, 9}));
}

TEST(ReplayTableTest, RefusesABatchWithAnotherObsSize) {
  ReplayTable table(Options(100));
  ASSERT_EQ(table.Insert(MakeBatch(0, 3, 4).view()), nullptr);
  const char* why = table.Insert(MakeBatch(3, 3, 5).view());
  ASSERT_NE(why, nullptr);
  EXPECT_NE(std::string(why).find("obs_size"), std::string::npos) << why;
  EXPECT_EQ(table.size(), 3);
  EXPECT_EQ(table.obs_size(), 4);
}

TEST(ReplayTableTest, RefusesABatchThatDoesNotMatchAConfiguredObsSize) {
  ReplayTable table(Options(100, 4));
  EXPECT_EQ(table.obs_size(), 4);
  EXPECT_NE(table.Insert(MakeBatch(0, 3, 8).view()), nullptr);
  EXPECT_EQ(table.size(), 0);
  EXPECT_EQ(table.Insert(MakeBatch(0, 3, 4).view()), nullptr);
}

TEST(ReplayTableTest, RefusesAnInconsistentBatchAndStoresNoneOfIt) {
  ReplayTable table(Options(100));
  OwnedBatch short_obs = MakeBatch(0, 3, 4);
  short_obs.obs.pop_back();
  EXPECT_NE(table.Insert(short_obs.view()), nullptr);
  OwnedBatch short_reward = MakeBatch(0, 3, 4);
  short_reward.reward.pop_back();
  EXPECT_NE(table.Insert(short_reward.view()), nullptr);
  OwnedBatch short_episode = MakeBatch(0, 3, 4);
  short_episode.episode_id.pop_back();
  EXPECT_NE(table.Insert(short_episode.view()), nullptr);
  OwnedBatch empty = MakeBatch(0, 0, 4);
  EXPECT_NE(table.Insert(empty.view()), nullptr);
  EXPECT_EQ(table.size(), 0);
  // A refused batch does not fix the observation size either.
  EXPECT_EQ(table.obs_size(), 0);
}

TEST(ReplayTableTest, StoresMinusOneWhenEpisodeIdsAreMissing) {
  ReplayTable table(Options(10));
  OwnedBatch b = MakeBatch(0, 2, 1);
  b.episode_id.clear();
  b.priority.clear();
  ASSERT_EQ(table.Insert(b.view()), nullptr);
  std::mt19937_64 rng(3);
  SampleBatch s;
  s.Resize(10, 1);
  ASSERT_TRUE(table.Sample(10, &rng, s.spans()));
  for (int64_t id : s.episode_id) EXPECT_EQ(id, -1);
}

TEST(ReplayTableTest, SampleOnAnEmptyTableReturnsFalse) {
  ReplayTable table(Options(10, 2));
  std::mt19937_64 rng(4);
  SampleBatch s;
  s.Resize(3, 2);
  EXPECT_FALSE(table.Sample(3, &rng, s.spans()));
  EXPECT_EQ(table.total_samples(), 0);
}

TEST(ReplayTableTest, SamplesOnlyStoredTransitionsBeforeTheBufferIsFull) {
  ReplayTable table(Options(1000));
  ASSERT_EQ(table.Insert(MakeBatch(0, 5, 3).view()), nullptr);
  std::mt19937_64 rng(5);
  SampleBatch s;
  s.Resize(2000, 3);
  ASSERT_TRUE(table.Sample(2000, &rng, s.spans()));
  std::set<int> seen;
  for (int i = 0; i < 2000; ++i) {
    ExpectConsistent(s, i);
    seen.insert(static_cast<int>(s.obs[static_cast<size_t>(i) * 3]));
  }
  EXPECT_EQ(seen, (std::set<int>{0, 1, 2, 3, 4}));
  EXPECT_EQ(table.total_samples(), 2000);
}

TEST(ReplayTableTest, SamplesUniformly) {
  // Chi-square test of 200000 draws over 20 stored transitions (after a wraparound, so that
  // overwritten slots are checked too). With 19 degrees of freedom, chi2 > 43.8 has probability
  // 0.001 under uniformity; the seed is fixed, so the outcome is deterministic.
  constexpr int kCapacity = 20;
  constexpr int kDraws = 200000;
  ReplayTable table(Options(kCapacity));
  ASSERT_EQ(table.Insert(MakeBatch(0, 27, 1).view()), nullptr);
  std::mt19937_64 rng(6);
  SampleBatch s;
  s.Resize(1000, 1);
  std::vector<int> hits(27, 0);
  for (int round = 0; round < kDraws / 1000; ++round) {
    ASSERT_TRUE(table.Sample(1000, &rng, s.spans()));
    for (float v : s.obs) ++hits[static_cast<size_t>(v)];
  }
  for (int v = 0; v < 7; ++v) EXPECT_EQ(hits[static_cast<size_t>(v)], 0) << v;
  const double expected = static_cast<double>(kDraws) / kCapacity;
  double chi2 = 0.0;
  for (int v = 7; v < 27; ++v) {
    const double d = hits[static_cast<size_t>(v)] - expected;
    chi2 += d * d / expected;
  }
  EXPECT_LT(chi2, 43.8);
  // A sharper per-bucket bound as well: 4 standard deviations (~ 4 * 97).
  for (int v = 7; v < 27; ++v) EXPECT_NEAR(hits[static_cast<size_t>(v)], expected, 400.0) << v;
}

TEST(ReplayTableTest, SameSeedSameSamples) {
  ReplayTable a(Options(50));
  ReplayTable b(Options(50));
  ASSERT_EQ(a.Insert(MakeBatch(0, 30, 2).view()), nullptr);
  ASSERT_EQ(b.Insert(MakeBatch(0, 30, 2).view()), nullptr);
  std::mt19937_64 rng_a(9);
  std::mt19937_64 rng_b(9);
  SampleBatch sa;
  SampleBatch sb;
  sa.Resize(64, 2);
  sb.Resize(64, 2);
  ASSERT_TRUE(a.Sample(64, &rng_a, sa.spans()));
  ASSERT_TRUE(b.Sample(64, &rng_b, sb.spans()));
  EXPECT_EQ(sa.index, sb.index);
}

TEST(ReplayTableDeathTest, AbortsWhenTheOutputHasTheWrongSize) {
  ReplayTable table(Options(10));
  ASSERT_EQ(table.Insert(MakeBatch(0, 3, 2).view()), nullptr);
  std::mt19937_64 rng(1);
  SampleBatch s;
  s.Resize(4, 2);
  EXPECT_DEATH(table.Sample(5, &rng, s.spans()), "batch_size");
}

}  // namespace
}  // namespace rl::replay
