#include "replay/sum_tree.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "common/check.h"

namespace rl::replay {
namespace {

// Largest capacity accepted: 2^40 leaves would already need 32 TiB.
constexpr int64_t kMaxCapacity = int64_t{1} << 40;
constexpr double kInfinity = std::numeric_limits<double>::infinity();

}  // namespace

SumTree::SumTree(int64_t capacity) : capacity_(capacity) {
  if (capacity < 1 || capacity > kMaxCapacity) {
    throw std::invalid_argument("SumTree: capacity must be in [1, 2^40], got " +
                                std::to_string(capacity));
  }
  leaves_ = 1;
  while (leaves_ < capacity) leaves_ *= 2;
  sum_.assign(static_cast<size_t>(2 * leaves_), 0.0);
  min_.assign(static_cast<size_t>(2 * leaves_), kInfinity);
}

void SumTree::Set(int64_t leaf, double value) {
  RL_CHECK(leaf >= 0 && leaf < capacity_) << "leaf " << leaf << " outside [0, " << capacity_ << ")";
  RL_CHECK(std::isfinite(value) && value >= 0.0)
      << "leaf value must be finite and >= 0, got " << value;
  // Write the leaf, then recompute every ancestor from its two children.
  auto node = static_cast<size_t>(leaves_ + leaf);
  sum_[node] = value;
  min_[node] = value > 0.0 ? value : kInfinity;
  for (node /= 2; node >= 1; node /= 2) {
    sum_[node] = sum_[2 * node] + sum_[2 * node + 1];
    min_[node] = std::min(min_[2 * node], min_[2 * node + 1]);
  }
}

double SumTree::Get(int64_t leaf) const {
  RL_CHECK(leaf >= 0 && leaf < capacity_) << "leaf " << leaf << " outside [0, " << capacity_ << ")";
  return sum_[static_cast<size_t>(leaves_ + leaf)];
}

int64_t SumTree::Find(double mass) const {
  RL_CHECK(Total() > 0.0) << "Find() on a tree whose leaves are all 0";
  // A mass at or beyond the total (or NaN) walks right wherever it can: the last non-zero leaf.
  if (!(mass < Total())) mass = kInfinity;
  if (mass < 0.0) mass = 0.0;
  // Descend from the root. A subtree of sum 0 is never entered: when the mass falls into the
  // right child but that is empty (a rounding error), take the left one, which then is not.
  size_t node = 1;
  const auto leaves = static_cast<size_t>(leaves_);
  while (node < leaves) {
    const size_t left = 2 * node;
    const double left_sum = sum_[left];
    if (mass < left_sum || sum_[left + 1] == 0.0) {
      node = left;
    } else {
      mass -= left_sum;
      node = left + 1;
    }
  }
  return static_cast<int64_t>(node - leaves);
}

std::span<const double> SumTree::leaves() const {
  return {sum_.data() + leaves_, static_cast<size_t>(capacity_)};
}

void SumTree::Assign(std::span<const double> values) {
  RL_CHECK(static_cast<int64_t>(values.size()) == capacity_)
      << "Assign() needs " << capacity_ << " values, got " << values.size();
  const auto first = static_cast<size_t>(leaves_);
  for (size_t i = 0; i < values.size(); ++i) {
    RL_CHECK(std::isfinite(values[i]) && values[i] >= 0.0)
        << "leaf value must be finite and >= 0, got " << values[i];
    sum_[first + i] = values[i];
    min_[first + i] = values[i] > 0.0 ? values[i] : kInfinity;
  }
  // Every parent from its two children, deepest first (as Set() computes each of them).
  for (size_t node = first - 1; node >= 1; --node) {
    sum_[node] = sum_[2 * node] + sum_[2 * node + 1];
    min_[node] = std::min(min_[2 * node], min_[2 * node + 1]);
  }
}

int64_t SumTree::memory_bytes() const {
  return static_cast<int64_t>((sum_.capacity() + min_.capacity()) * sizeof(double));
}

}  // namespace rl::replay
