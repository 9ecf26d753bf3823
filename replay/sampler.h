// Sampler: chooses which stored transitions a batch is drawn from.
//
// A ReplayTable stores transitions in slots 0 .. capacity-1 and tells its sampler which slots
// hold data; the sampler alone decides how they are drawn (uniformly now, by priority later).
// Implementations see slot numbers only, never the transitions themselves.
//
// Member methods will not be called concurrently, so implementations do not need to be
// thread-safe.
#pragma once

#include <cstdint>
#include <random>
#include <span>

namespace rl::replay {

/// One draw: the slot chosen and the probability with which it was chosen (for importance
/// weights).
struct SampledItem {
  int64_t slot = -1;
  double probability = 0.0;
};

class Sampler {
 public:
  Sampler() = default;
  Sampler(const Sampler&) = delete;
  Sampler& operator=(const Sampler&) = delete;
  virtual ~Sampler() = default;

  /// Slot `slot` (0 <= slot < capacity) now holds a new transition. A slot that already held
  /// one is replaced (the old transition is gone). `priority` >= 0 is the transition's initial
  /// priority; samplers that do not prioritize ignore it.
  virtual void Insert(int64_t slot, double priority) = 0;

  /// Fills every element of `out` with an independent draw, with replacement, among the slots
  /// inserted so far. Must not be called while size() == 0.
  virtual void Sample(std::mt19937_64* rng, std::span<SampledItem> out) = 0;

  /// Number of distinct slots that hold a transition.
  virtual int64_t size() const = 0;
};

}  // namespace rl::replay
