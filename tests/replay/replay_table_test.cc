#include "replay/replay_table.h"

#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <random>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "replay/prioritized_sampler.h"

namespace rl::replay {
namespace {

// Transitions whose every field is derived from their number v, so that a sampled transition
// can be checked field by field: obs = {v, v + 0.25, ...}, next_obs = obs + 100,
// action = v % 3, reward = 2v, discount = 0.5 when v is odd else 1, episode_id = v / 10.
struct OwnedBatch {
  int obs_size = 0;
  int count = 0;
  int action_width = 1;
  std::vector<float> obs, next_obs, reward, discount, priority;
  std::vector<float> action;
  std::vector<int64_t> episode_id;

  TransitionBatchView view() const {
    TransitionBatchView v;
    v.obs_size = obs_size;
    v.count = count;
    v.obs = obs;
    v.next_obs = next_obs;
    v.columns = ColumnsView{action_width, action, reward, discount, episode_id, priority};
    return v;
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
    b.action.push_back(static_cast<float>(v % 3));
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

// As ExpectConsistent(), whatever the weight.
void ExpectConsistentButWeight(const SampleBatch& s, int i) {
  const auto k = static_cast<size_t>(i);
  const auto obs_size = static_cast<size_t>(s.obs_size);
  const float v = s.obs[k * obs_size];
  ASSERT_EQ(static_cast<float>(s.index[k]), v);
  for (size_t j = 0; j < obs_size; ++j) {
    EXPECT_EQ(s.next_obs[k * obs_size + j], v + 0.25f * static_cast<float>(j) + 100.0f);
  }
  EXPECT_EQ(s.reward[k], 2.0f * v);
}

// A batch of `count` transitions of the table's shapes.
SampleBatch BatchFor(const ReplayTable& table, int count) {
  SampleBatch s;
  s.Resize(count, table.obs_size(), table.action_width());
  return s;
}

// Resizes `s` to `count` transitions of the table's shapes and draws them with a generator seeded
// with `seed`; returns what Sample() returns.
bool Draw(ReplayTable* table, int count, uint64_t seed, SampleBatch* s) {
  std::mt19937_64 rng(seed);
  *s = BatchFor(*table, count);
  return table->Sample(count, &rng, s->spans());
}

// Draws `count` transitions (Draw()) and checks each with ExpectConsistent() and that its index
// is its insert number; returns the numbers drawn.
std::set<int> DrawAndCheck(ReplayTable* table, int count, uint64_t seed) {
  SampleBatch s;
  EXPECT_TRUE(Draw(table, count, seed, &s));
  std::set<int> seen;
  for (int i = 0; i < count; ++i) {
    ExpectConsistent(s, i);
    const auto v =
        static_cast<int>(s.obs[static_cast<size_t>(i) * static_cast<size_t>(s.obs_size)]);
    EXPECT_EQ(s.index[static_cast<size_t>(i)], v);
    seen.insert(v);
  }
  return seen;
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
  ReplayTable table(Options(8));
  // 11 transitions in uneven batches, so that one batch wraps around the end.
  ASSERT_EQ(table.Insert(MakeBatch(0, 5, 2).view()), nullptr);
  ASSERT_EQ(table.Insert(MakeBatch(5, 5, 2).view()), nullptr);
  ASSERT_EQ(table.Insert(MakeBatch(10, 1, 2).view()), nullptr);
  EXPECT_EQ(table.size(), 8);
  EXPECT_EQ(table.total_inserts(), 11);
  // The first 3 are gone, all the others are there.
  EXPECT_EQ(DrawAndCheck(&table, 500, /*seed=*/1), (std::set<int>{3, 4, 5, 6, 7, 8, 9, 10}));
}

TEST(ReplayTableTest, ABatchLargerThanTheCapacityKeepsItsNewestTransitions) {
  ReplayTable table(Options(4));
  ASSERT_EQ(table.Insert(MakeBatch(0, 10, 1).view()), nullptr);
  EXPECT_EQ(table.size(), 4);
  SampleBatch s;
  ASSERT_TRUE(Draw(&table, 200, /*seed=*/2, &s));
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
  SampleBatch s;
  ASSERT_TRUE(Draw(&table, 10, /*seed=*/3, &s));
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
  EXPECT_EQ(DrawAndCheck(&table, 2000, /*seed=*/5), (std::set<int>{0, 1, 2, 3, 4}));
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
  SampleBatch s = BatchFor(table, 1000);
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
  SampleBatch sa;
  SampleBatch sb;
  ASSERT_TRUE(Draw(&a, 64, /*seed=*/9, &sa));
  ASSERT_TRUE(Draw(&b, 64, /*seed=*/9, &sb));
  EXPECT_EQ(sa.index, sb.index);
}

TEST(ReplayTableTest, UniformWeightsAreOneForAnyExponent) {
  ReplayTable table(Options(10));
  ASSERT_EQ(table.Insert(MakeBatch(0, 7, 1).view()), nullptr);
  std::mt19937_64 rng(12);
  SampleBatch s = BatchFor(table, 50);
  for (double beta : {0.0, 0.4, 1.0}) {
    table.set_importance_exponent(beta);
    ASSERT_TRUE(table.Sample(50, &rng, s.spans()));
    for (float w : s.weight) ASSERT_EQ(w, 1.0f);
  }
  EXPECT_EQ(table.sampler().MinProbability(), 1.0 / 7.0);
}

TEST(ReplayTableTest, RefusesAnImportanceExponentOutsideZeroOne) {
  ReplayTable table(Options(10));
  EXPECT_EQ(table.importance_exponent(), 1.0);
  EXPECT_THROW(table.set_importance_exponent(-0.1), std::invalid_argument);
  EXPECT_THROW(table.set_importance_exponent(1.5), std::invalid_argument);
  EXPECT_THROW(table.set_importance_exponent(std::numeric_limits<double>::quiet_NaN()),
               std::invalid_argument);
  table.set_importance_exponent(0.4);
  EXPECT_EQ(table.importance_exponent(), 0.4);
}

TEST(ReplayTableTest, ImportanceWeightsOfThreeTransitionsMatchAHandComputation) {
  // w_i = (N P_i)^-beta / max_j (N P_j)^-beta with N = 3. The largest is that of P = 1/8:
  //   beta = 1:   (3/8)^-1 = 8/3,  (6/8)^-1 = 4/3,  (15/8)^-1 = 8/15  ->  1, 1/2, 1/5
  //   beta = 0.5: sqrt of those ratios                                 ->  1, 0.70711, 0.44721
  //   beta = 0:   1, 1, 1
  struct Case {
    double beta;
    float w[3];
  };
  const Case cases[] = {{1.0, {1.0f, 0.5f, 0.2f}},
                        {0.5, {1.0f, 0.70710678f, 0.44721360f}},
                        {0.0, {1.0f, 1.0f, 1.0f}}};
  // Three transitions of priorities 1, 2 and 5 (alpha 1, epsilon negligible): P = 1/8, 2/8, 5/8.
  ReplayTable table(Options(8), std::make_unique<PrioritizedSampler>(8, 1.0, 1e-9));
  OwnedBatch b = MakeBatch(0, 3, 2);
  b.priority = {1.0f, 2.0f, 5.0f};
  ASSERT_EQ(table.Insert(b.view()), nullptr);
  std::mt19937_64 rng(13);
  SampleBatch s = BatchFor(table, 8000);
  for (const Case& c : cases) {
    table.set_importance_exponent(c.beta);
    ASSERT_TRUE(table.Sample(8000, &rng, s.spans()));
    std::vector<int> hits(3, 0);
    for (size_t i = 0; i < 8000; ++i) {
      ExpectConsistentButWeight(s, static_cast<int>(i));
      const int64_t v = s.index[i];
      ASSERT_TRUE(v >= 0 && v < 3) << v;
      EXPECT_NEAR(s.weight[i], c.w[v], 1e-6) << "beta " << c.beta << " index " << v;
      ++hits[static_cast<size_t>(v)];
    }
    // Stratified draws of 8000: each count within a few of 1000, 2000, 5000.
    EXPECT_NEAR(hits[0], 1000, 5);
    EXPECT_NEAR(hits[1], 2000, 5);
    EXPECT_NEAR(hits[2], 5000, 5);
  }
}

TEST(ReplayTableTest, UpdatePrioritiesSkipsOverwrittenAndUnknownTransitions) {
  // Capacity 4 after 6 inserts: transitions 2 .. 5 are stored (slots 2, 3, 0, 1).
  ReplayTable table(Options(4), std::make_unique<PrioritizedSampler>(4, 1.0, 1e-9));
  ASSERT_EQ(table.Insert(MakeBatch(0, 6, 1).view()), nullptr);
  const std::vector<int64_t> index = {0, 1, 2, 5, 6, -1, 3, 4};
  const std::vector<float> priority = {9, 9, 100, 50, 9, 9, std::numeric_limits<float>::quiet_NaN(),
                                       -1};
  EXPECT_EQ(table.UpdatePriorities(index, priority), 2);
  // Transitions 2 (slot 2) and 5 (slot 1) took 100 and 50; 3 and 4 kept the initial 1.
  const Sampler& sampler = table.sampler();
  EXPECT_NEAR(sampler.Probability(2), 100.0 / 152.0, 1e-6);
  EXPECT_NEAR(sampler.Probability(1), 50.0 / 152.0, 1e-6);
  EXPECT_NEAR(sampler.Probability(3), 1.0 / 152.0, 1e-6);
  EXPECT_NEAR(sampler.Probability(0), 1.0 / 152.0, 1e-6);
  // Nothing stored yet: everything is skipped.
  ReplayTable empty(Options(4));
  EXPECT_EQ(empty.UpdatePriorities(index, priority), 0);
}

TEST(ReplayTableTest, UpdatePrioritiesOfSampledTransitionsSteersTheSampler) {
  ReplayTable table(Options(16), std::make_unique<PrioritizedSampler>(16, 1.0, 1e-6));
  ASSERT_EQ(table.Insert(MakeBatch(0, 16, 1).view()), nullptr);
  std::mt19937_64 rng(14);
  SampleBatch s = BatchFor(table, 16);
  ASSERT_TRUE(table.Sample(16, &rng, s.spans()));
  // The learner finds every TD error 0 except that of transition 7.
  std::vector<float> priority(16, 0.0f);
  for (size_t i = 0; i < 16; ++i) {
    if (s.index[i] == 7) priority[i] = 1.0f;
  }
  EXPECT_EQ(table.UpdatePriorities(s.index, priority), 16);
  // Every sampled transition (with stratified draws over 16 equal priorities, all of them)
  // now has priority ~0 except 7.
  ASSERT_TRUE(table.Sample(16, &rng, s.spans()));
  for (int64_t v : s.index) EXPECT_EQ(v, 7);
}

TEST(ReplayTableTest, ReportsItsMemory) {
  // Per slot: 2 * 4 floats of observations, 4 bytes per action float, 24 of other fields, 16 of
  // uniform sampler; allocated once the action width is known.
  ReplayTableOptions options = Options(1000, 4);
  options.action_width = 1;
  ReplayTable table(options);
  EXPECT_EQ(table.memory_bytes(), 1000 * (32 + 4 + 24 + 16));
  // With a prioritized sampler: its tree of 2 * 1024 nodes of two doubles instead.
  ReplayTable prioritized(options, std::make_unique<PrioritizedSampler>(1000, 0.6));
  EXPECT_EQ(prioritized.memory_bytes(), 1000 * (32 + 4 + 24) + 32 * 1024);
  // Three action floats: 8 more bytes a slot.
  options.action_width = 3;
  ReplayTable wide(options);
  EXPECT_EQ(wide.memory_bytes(), 1000 * (32 + 12 + 24 + 16));
}

// Actions are stored as action_width floats, whatever the width; a batch of another width than
// the table's is refused whole.
TEST(ReplayTableTest, StoresActionVectorsOfTheTablesWidth) {
  ReplayTable table(Options(100, 2));
  OwnedBatch b = MakeBatch(0, 5, 2);
  b.action_width = 3;
  b.action.clear();
  for (int v = 0; v < 5; ++v) {
    b.action.insert(b.action.end(), {static_cast<float>(v), -0.5f, 0.125f * static_cast<float>(v)});
  }
  ASSERT_EQ(table.Insert(b.view()), nullptr);
  EXPECT_EQ(table.action_width(), 3);
  OwnedBatch narrow = MakeBatch(5, 2, 2);
  EXPECT_STREQ(table.Insert(narrow.view()), "action_width differs from the table's");
  b.action.pop_back();
  EXPECT_STREQ(table.Insert(b.view()), "action size is not count * action_width");
  EXPECT_EQ(table.size(), 5);
  SampleBatch s;
  ASSERT_TRUE(Draw(&table, 20, /*seed=*/3, &s));
  for (size_t i = 0; i < 20; ++i) {
    const float v = s.obs[2 * i];
    EXPECT_EQ(s.action[3 * i], v);
    EXPECT_EQ(s.action[3 * i + 1], -0.5f);
    EXPECT_EQ(s.action[3 * i + 2], 0.125f * v);
  }
}

TEST(ReplayTableDeathTest, AbortsWhenTheOutputHasTheWrongSize) {
  ReplayTable table(Options(10));
  ASSERT_EQ(table.Insert(MakeBatch(0, 3, 2).view()), nullptr);
  std::mt19937_64 rng(1);
  SampleBatch s = BatchFor(table, 4);
  EXPECT_DEATH(table.Sample(5, &rng, s.spans()), "batch_size");
}

}  // namespace
}  // namespace rl::replay
