#include "replay/sum_tree.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <stdexcept>
#include <vector>

#include <gtest/gtest.h>

namespace rl::replay {
namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();

// The leaf whose cumulative range contains `mass`, by a linear scan.
int64_t BruteForceFind(const std::vector<double>& leaves, double mass) {
  double before = 0.0;
  for (size_t i = 0; i < leaves.size(); ++i) {
    if (leaves[i] > 0.0 && mass < before + leaves[i]) return static_cast<int64_t>(i);
    before += leaves[i];
  }
  return -1;
}

TEST(SumTreeTest, RefusesABadCapacity) {
  EXPECT_THROW(SumTree(0), std::invalid_argument);
  EXPECT_THROW(SumTree(-3), std::invalid_argument);
}

TEST(SumTreeTest, StartsWithEveryLeafZero) {
  SumTree tree(5);
  EXPECT_EQ(tree.capacity(), 5);
  EXPECT_EQ(tree.Total(), 0.0);
  EXPECT_EQ(tree.Min(), kInfinity);
  for (int64_t leaf = 0; leaf < 5; ++leaf) EXPECT_EQ(tree.Get(leaf), 0.0);
}

TEST(SumTreeTest, MatchesABruteForceReferenceUnderRandomOperations) {
  // Values are multiples of 1/4 below 100, so every sum is exact and Find() must agree with the
  // linear scan to the leaf, boundaries included. 37 leaves: not a power of two.
  constexpr int64_t kCapacity = 37;
  SumTree tree(kCapacity);
  std::vector<double> reference(kCapacity, 0.0);
  std::mt19937_64 rng(11);
  std::uniform_int_distribution<int64_t> pick_leaf(0, kCapacity - 1);
  std::uniform_int_distribution<int> pick_quarters(1, 400);
  std::bernoulli_distribution zero(0.3);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (int op = 0; op < 5000; ++op) {
    const int64_t leaf = pick_leaf(rng);
    const double value = zero(rng) ? 0.0 : 0.25 * pick_quarters(rng);
    tree.Set(leaf, value);
    reference[static_cast<size_t>(leaf)] = value;

    double total = 0.0;
    double min = kInfinity;
    for (double v : reference) {
      total += v;
      if (v > 0.0) min = std::min(min, v);
    }
    ASSERT_EQ(tree.Total(), total) << "op " << op;
    ASSERT_EQ(tree.Min(), min) << "op " << op;
    ASSERT_EQ(tree.Get(leaf), value);
    if (total == 0.0) continue;
    // Random masses, and every boundary between cumulative ranges.
    for (int k = 0; k < 10; ++k) {
      const double mass = unit(rng) * total;
      ASSERT_EQ(tree.Find(mass), BruteForceFind(reference, mass)) << "op " << op << " " << mass;
    }
    if (op % 50 == 0) {
      double before = 0.0;
      int64_t last = -1;
      for (size_t i = 0; i < reference.size(); ++i) {
        if (reference[i] == 0.0) continue;
        ASSERT_EQ(tree.Find(before), static_cast<int64_t>(i)) << before;
        before += reference[i];
        last = static_cast<int64_t>(i);
      }
      // The total itself (a rounding case): the last non-zero leaf.
      ASSERT_EQ(tree.Find(total), last);
    }
  }
}

TEST(SumTreeTest, FindHandlesBoundariesAndSkipsZeroLeaves) {
  SumTree tree(5);
  tree.Set(1, 1.0);
  tree.Set(3, 2.0);
  // Leaves: 0 1 0 2 0, total 3. Leaf 1 covers [0, 1), leaf 3 covers [1, 3).
  EXPECT_EQ(tree.Find(0.0), 1);
  EXPECT_EQ(tree.Find(0.5), 1);
  EXPECT_EQ(tree.Find(std::nextafter(1.0, 0.0)), 1);
  EXPECT_EQ(tree.Find(1.0), 3);
  EXPECT_EQ(tree.Find(std::nextafter(3.0, 0.0)), 3);
  // At or beyond the total (rounding): the last non-zero leaf, never a zero leaf after it.
  EXPECT_EQ(tree.Find(3.0), 3);
  EXPECT_EQ(tree.Find(1e300), 3);
  EXPECT_EQ(tree.Find(kInfinity), 3);
  // Below 0: the first non-zero leaf.
  EXPECT_EQ(tree.Find(-1.0), 1);
}

TEST(SumTreeTest, FindBeyondTheTotalGivesTheLastNonZeroLeafEvenWhenItIsTheFirst) {
  SumTree tree(6);
  tree.Set(0, 5.0);
  EXPECT_EQ(tree.Find(5.0), 0);
  EXPECT_EQ(tree.Find(100.0), 0);
  tree.Set(0, 0.0);
  tree.Set(5, 0.5);
  EXPECT_EQ(tree.Find(0.0), 5);
  EXPECT_EQ(tree.Find(0.5), 5);
}

TEST(SumTreeTest, FindNeverReturnsAZeroLeafWhenTheTotalIsInexact) {
  // Sums of 0.1 are inexact: a mass just under the computed total must still land on a leaf
  // that holds mass.
  SumTree tree(1000);
  for (int64_t leaf = 0; leaf < 1000; leaf += 3) tree.Set(leaf, 0.1);
  for (double mass : {tree.Total(), std::nextafter(tree.Total(), 0.0), tree.Total() - 1e-12}) {
    const int64_t leaf = tree.Find(mass);
    EXPECT_GT(tree.Get(leaf), 0.0) << leaf;
  }
  EXPECT_EQ(tree.Find(tree.Total()), 999);
}

TEST(SumTreeTest, MinIgnoresZeroLeaves) {
  SumTree tree(4);
  tree.Set(0, 3.0);
  tree.Set(2, 0.5);
  EXPECT_EQ(tree.Min(), 0.5);
  tree.Set(2, 0.0);
  EXPECT_EQ(tree.Min(), 3.0);
  tree.Set(0, 0.0);
  EXPECT_EQ(tree.Min(), kInfinity);
}

TEST(SumTreeTest, TotalsDoNotDriftAfterLargeValuesComeAndGo) {
  // Adjusting ancestors by differences would leave 0.1 + 1e20 - 1e20 = 0 behind.
  SumTree tree(8);
  tree.Set(0, 0.1);
  for (int i = 0; i < 100; ++i) {
    tree.Set(7, 1e20);
    tree.Set(7, 0.0);
  }
  EXPECT_EQ(tree.Total(), 0.1);
  EXPECT_EQ(tree.Find(0.05), 0);
}

TEST(SumTreeTest, ReportsTheMemoryOfItsTwoArrays) {
  // 1000 leaves round up to 1024: two arrays of 2048 doubles.
  EXPECT_EQ(SumTree(1000).memory_bytes(), 2 * 2048 * 8);
  EXPECT_EQ(SumTree(1).memory_bytes(), 2 * 2 * 8);
}

TEST(SumTreeDeathTest, AbortsOnABadLeafOrValue) {
  SumTree tree(4);
  EXPECT_DEATH(tree.Set(4, 1.0), "leaf");
  EXPECT_DEATH(tree.Set(0, -1.0), "finite");
  EXPECT_DEATH(tree.Set(0, std::numeric_limits<double>::quiet_NaN()), "finite");
  EXPECT_DEATH(tree.Find(0.0), "all 0");
}

TEST(SumTreeTest, AssignBuildsTheTreeThatSetGives) {
  for (int64_t capacity : {1, 2, 5, 64, 1000}) {
    std::mt19937_64 rng(static_cast<uint64_t>(capacity));
    std::uniform_real_distribution<double> value(0.0, 3.0);
    std::vector<double> leaves(static_cast<size_t>(capacity));
    SumTree by_set(capacity);
    for (int64_t i = 0; i < capacity; ++i) {
      leaves[static_cast<size_t>(i)] = i % 3 == 0 ? 0.0 : value(rng);
      by_set.Set(i, leaves[static_cast<size_t>(i)]);
    }
    SumTree assigned(capacity);
    assigned.Set(0, 9.0);  // replaced
    assigned.Assign(leaves);
    EXPECT_EQ(assigned.Total(), by_set.Total()) << capacity;
    EXPECT_EQ(assigned.Min(), by_set.Min()) << capacity;
    EXPECT_EQ(std::vector<double>(assigned.leaves().begin(), assigned.leaves().end()), leaves);
    for (double mass = 0.0; mass < by_set.Total(); mass += by_set.Total() / 37) {
      EXPECT_EQ(assigned.Find(mass), by_set.Find(mass)) << capacity << " " << mass;
    }
  }
}

}  // namespace
}  // namespace rl::replay
