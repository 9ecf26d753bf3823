#include "replay/prioritized_sampler.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "common/check.h"

namespace rl::replay {
namespace {

// Bounds of a stored value: far from overflow of a sum over 2^40 leaves, and far from 0, which
// would make a stored slot undrawable.
constexpr double kMinStored = 1e-200;
constexpr double kMaxStored = 1e200;

// `capacity`, or an exception when it is below 1.
int64_t CheckedCapacity(int64_t capacity) {
  if (capacity < 1) {
    throw std::invalid_argument("PrioritizedSampler: capacity must be at least 1, got " +
                                std::to_string(capacity));
  }
  return capacity;
}

}  // namespace

PrioritizedSampler::PrioritizedSampler(int64_t capacity, double alpha, double epsilon)
    : tree_(CheckedCapacity(capacity)), alpha_(alpha), epsilon_(epsilon) {
  if (!std::isfinite(alpha) || alpha < 0.0) {
    throw std::invalid_argument("PrioritizedSampler: alpha must be finite and >= 0, got " +
                                std::to_string(alpha));
  }
  if (!std::isfinite(epsilon) || epsilon <= 0.0) {
    throw std::invalid_argument("PrioritizedSampler: epsilon must be finite and > 0, got " +
                                std::to_string(epsilon));
  }
}

double PrioritizedSampler::Stored(double priority) const {
  const double v = std::pow(priority + epsilon_, alpha_);
  // pow of a finite positive base is never NaN; it may overflow or underflow for extreme alpha.
  return std::clamp(v, kMinStored, kMaxStored);
}

void PrioritizedSampler::See(double priority) {
  if (priority <= 0.0) return;
  max_priority_ = seen_priority_ ? std::max(max_priority_, priority) : priority;
  seen_priority_ = true;
}

void PrioritizedSampler::Insert(int64_t slot, double priority) {
  // A known priority also raises the maximum; an unknown one takes it.
  const bool known = std::isfinite(priority) && priority > 0.0;
  if (known) See(priority);
  if (tree_.Get(slot) == 0.0) ++size_;
  tree_.Set(slot, Stored(known ? priority : max_priority_));
}

void PrioritizedSampler::Update(int64_t slot, double priority) {
  if (tree_.Get(slot) == 0.0) return;  // no transition there
  if (!std::isfinite(priority) || priority < 0.0) return;
  See(priority);
  tree_.Set(slot, Stored(priority));
}

void PrioritizedSampler::Remove(int64_t slot) {
  if (tree_.Get(slot) == 0.0) return;
  tree_.Set(slot, 0.0);
  --size_;
}

void PrioritizedSampler::Sample(std::mt19937_64* rng, std::span<SampledItem> out) {
  RL_CHECK(size_ > 0) << "Sample() called on an empty sampler";
  // One uniform mass in each of out.size() equal segments of the total.
  const double total = tree_.Total();
  const double segment = total / static_cast<double>(out.size());
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  for (size_t i = 0; i < out.size(); ++i) {
    const double mass = (static_cast<double>(i) + uniform(*rng)) * segment;
    // Find() maps a mass that rounding pushed to the total or beyond onto the last leaf.
    const int64_t slot = tree_.Find(mass);
    out[i].slot = slot;
    out[i].probability = tree_.Get(slot) / total;
  }
}

double PrioritizedSampler::Probability(int64_t slot) const {
  const double v = tree_.Get(slot);
  return v == 0.0 ? 0.0 : v / tree_.Total();
}

double PrioritizedSampler::MinProbability() const {
  return size_ == 0 ? 0.0 : tree_.Min() / tree_.Total();
}

}  // namespace rl::replay
