#include "replay/prioritized_sampler.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include "common/check.h"
#include "common/state_file.h"

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

void PrioritizedSampler::Save(const std::string& prefix, StateStream* out) const {
  out->PutText(prefix + "kind", "prioritized");
  const double params[] = {alpha_, epsilon_, max_priority_};
  out->PutDoubles(prefix + "params", params);
  out->PutInt(prefix + "seen_priority", seen_priority_ ? 1 : 0);
  out->AddDoubles(prefix + "values", tree_.leaves());
}

void PrioritizedSampler::Restore(const std::string& prefix, const StateView& in,
                                 std::span<const int64_t> insert_number) {
  const int64_t capacity = tree_.capacity();
  RL_CHECK(static_cast<int64_t>(insert_number.size()) == capacity)
      << "insert_number must have one entry per slot";
  const std::string kind = in.Text(prefix + "kind");
  if (kind != "prioritized") {
    throw std::runtime_error("the snapshot's sampler is " + kind + ", this replay's prioritized");
  }
  double params[3] = {};
  in.Copy<double>(prefix + "params", params);
  if (params[0] != alpha_ || params[1] != epsilon_) {
    throw std::runtime_error("the snapshot's priorities have alpha " + std::to_string(params[0]) +
                             " and epsilon " + std::to_string(params[1]) + ", this replay's " +
                             std::to_string(alpha_) + " and " + std::to_string(epsilon_));
  }
  if (!std::isfinite(params[2]) || params[2] <= 0.0) {
    throw std::runtime_error("section '" + prefix + "params' has a bad largest priority");
  }
  const int64_t seen = in.Int(prefix + "seen_priority");
  // A value per slot: within the stored bounds where a transition is, 0 elsewhere.
  std::vector<double> values(static_cast<size_t>(capacity));
  in.Copy<double>(prefix + "values", values);
  int64_t size = 0;
  for (int64_t slot = 0; slot < capacity; ++slot) {
    const double v = values[static_cast<size_t>(slot)];
    const bool stored = insert_number[static_cast<size_t>(slot)] >= 0;
    if (stored ? !(v >= kMinStored && v <= kMaxStored) : v != 0.0) {
      throw std::runtime_error("section '" + prefix + "values' disagrees with the table at slot " +
                               std::to_string(slot));
    }
    size += stored ? 1 : 0;
  }
  tree_.Assign(values);
  max_priority_ = params[2];
  seen_priority_ = seen != 0;
  size_ = size;
}

}  // namespace rl::replay
