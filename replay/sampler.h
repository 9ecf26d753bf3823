// Sampler: chooses which stored transitions a batch is drawn from.
//
// A table (ReplayTable, PixelTable) stores transitions in slots 0 .. capacity-1 and tells its
// sampler which slots hold data; the sampler alone decides how they are drawn (uniformly, or in
// proportion to priority). Implementations see slot numbers only, never the transitions
// themselves.
//
// Member methods will not be called concurrently, so implementations do not need to be
// thread-safe.
#pragma once

#include <cmath>
#include <cstdint>
#include <random>
#include <span>
#include <string>

#include "common/state_fwd.h"

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
  /// one is replaced (the old transition is gone). `priority` is the transition's initial
  /// priority (|TD error|) when it is finite and > 0; anything else means "not known yet".
  /// Samplers that do not prioritize ignore it.
  virtual void Insert(int64_t slot, double priority) = 0;

  /// The transition in `slot` has a new priority (|TD error|, >= 0). Slots that hold no
  /// transition are ignored. Samplers that do not prioritize ignore the call.
  virtual void Update(int64_t /*slot*/, double /*priority*/) {}

  /// The transition in `slot` is gone: the slot is never drawn again until the next Insert() to
  /// it. Slots that hold no transition are ignored.
  virtual void Remove(int64_t slot) = 0;

  /// Fills every element of `out` with a draw, with replacement, among the slots that hold a
  /// transition, each with the probability it was drawn with. Must not be called while
  /// size() == 0.
  virtual void Sample(std::mt19937_64* rng, std::span<SampledItem> out) = 0;

  /// Probability with which a single draw would choose `slot` now (0 when it holds no
  /// transition).
  virtual double Probability(int64_t slot) const = 0;

  /// Smallest Probability() of any slot that holds a transition (0 when size() == 0). Tables use
  /// it to normalise importance weights by their largest possible value.
  virtual double MinProbability() const = 0;

  /// Number of distinct slots that hold a transition.
  virtual int64_t size() const = 0;

  /// Bytes of memory held (the capacities of its arrays).
  virtual int64_t memory_bytes() const = 0;

  /// Adds the sampler's state to a snapshot, as sections named `prefix` + "...": its kind and
  /// parameters are copied, its per-slot arrays referred to (they must stay unchanged until the
  /// snapshot is written). O(1) besides the section entries.
  virtual void Save(const std::string& prefix, StateStream* out) const = 0;
  /// Replaces the sampler's state by the one Save() wrote, for a table whose slot s holds a
  /// transition exactly when insert_number[s] >= 0 (one entry per slot). Throws
  /// std::runtime_error naming the section when the snapshot's sampler is of another kind or
  /// parameters, or inconsistent with the table (a slot drawable that holds nothing, or the
  /// other way round, a slot out of range or twice). O(capacity); allocates O(capacity) at most.
  virtual void Restore(const std::string& prefix, const StateView& in,
                       std::span<const int64_t> insert_number) = 0;
};

/// Importance-sampling weight of a draw made with probability `probability` (Schaul et al.
/// 2016, section 3.4): (N * P(i))^-beta / max_j (N * P(j))^-beta over all N stored transitions,
/// which is (min_probability / probability)^beta, in [0, 1]. beta in [0, 1]; beta = 0 and
/// uniform sampling give exactly 1.
inline float ImportanceWeight(double probability, double min_probability, double beta) {
  if (beta == 0.0 || probability <= min_probability) return 1.0f;
  return static_cast<float>(std::pow(min_probability / probability, beta));
}

}  // namespace rl::replay
