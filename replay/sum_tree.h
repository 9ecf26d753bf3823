// SumTree: `capacity` non-negative values (leaves) with O(log N) update, their total, their
// smallest non-zero value, and O(log N) lookup of the leaf that a cumulative mass falls into,
// the data structure behind proportional prioritized replay (Schaul et al. 2016, "Prioritized
// Experience Replay", Appendix B.2.1).
//
// Layout: a complete binary tree over L leaves, L the smallest power of two >= capacity, stored
// as arrays of 2L doubles with the root at 1 and the children of node k at 2k and 2k+1; leaf i
// is node L + i, leaves at and beyond capacity stay 0. One array holds the sums of subtrees, a
// second one the minimum of their non-zero leaves (+infinity when all are 0). A parent is
// always recomputed from its two children, never adjusted by a difference, so rounding errors
// do not accumulate however many updates are made.
//
// Memory: 32 * L bytes, allocated by the constructor; nothing is allocated afterwards. Not
// thread-safe.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

namespace rl::replay {

class SumTree {
 public:
  /// All leaves start at 0. Throws std::invalid_argument when capacity < 1 or above 2^40.
  explicit SumTree(int64_t capacity);

  /// Sets leaf `leaf` (0 <= leaf < capacity) to `value` (finite, >= 0; anything else is a caller
  /// bug and aborts). O(log N).
  void Set(int64_t leaf, double value);
  /// The value of leaf `leaf`. O(1).
  double Get(int64_t leaf) const;
  /// Sum of all leaves. O(1).
  double Total() const { return sum_[1]; }
  /// Smallest non-zero leaf, or +infinity when every leaf is 0. O(1).
  double Min() const { return min_[1]; }

  /// The leaf whose cumulative range [sum of the leaves before it, that + its value) contains
  /// `mass`, for 0 <= mass < Total(); a leaf of value 0 is never returned. A mass at or beyond
  /// Total() (a rounding error of the caller's) gives the last non-zero leaf, a negative one the
  /// first. Must not be called while Total() == 0. O(log N).
  int64_t Find(double mass) const;

  /// The capacity() leaf values, in leaf order (for snapshots). O(1).
  std::span<const double> leaves() const;
  /// Sets every leaf at once (values finite and >= 0; anything else is a caller bug and aborts),
  /// rebuilding the tree bottom-up: the same tree as Set() of each leaf gives. O(N).
  void Assign(std::span<const double> values);

  int64_t capacity() const { return capacity_; }
  /// Bytes held by the two arrays.
  int64_t memory_bytes() const;

 private:
  int64_t capacity_ = 0;
  int64_t leaves_ = 0;       // L: leaf i is node leaves_ + i
  std::vector<double> sum_;  // by node: sum of the subtree's leaves
  std::vector<double> min_;  // by node: smallest non-zero leaf of the subtree, or +infinity
};

}  // namespace rl::replay
