// PrioritizedSampler: proportional prioritized replay (Schaul et al. 2016, "Prioritized
// Experience Replay", section 3.3), as used by Ape-X (Horgan et al. 2018).
//
// A slot's priority p is the |TD error| of its transition, as sent by the learner (or, in Ape-X,
// computed by the actor that generated it). The sampler stores
//
//   v = (p + epsilon)^alpha
//
// and draws slot i with probability P(i) = v_i / sum_k v_k. epsilon > 0 keeps every stored
// transition drawable even when its TD error is 0; alpha = 0 is uniform sampling, alpha = 1
// fully proportional. (v is kept within [1e-200, 1e200], which only matters for extreme alpha.)
//
// A transition inserted without a priority (Insert() with a priority that is not finite and
// > 0) gets the largest priority seen so far, so that it is likely to be replayed at least
// once; before any priority has been seen that is 1. "Seen" counts every positive priority
// given to Insert() or applied by Update(), including ones since overwritten or lowered: the
// maximum never decreases once the first priority has replaced the initial 1. (A priority of 0
// is not counted, so that a learner whose first TD errors are all 0 does not make new
// transitions the least likely ones.)
//
// Sample() is stratified: for a batch of k draws the total is split into k equal segments and
// one mass is drawn uniformly within each, which lowers the variance of a batch's composition
// without changing each draw's marginal probability v_i / sum.
//
// Memory: about 32 * capacity bytes (up to 64 when capacity is just above a power of two), all
// allocated by the constructor. Insert, Update, Remove: O(log capacity); Sample: O(k log
// capacity), no allocation. Not thread-safe.
#pragma once

#include <cstdint>
#include <random>
#include <span>

#include "replay/sampler.h"
#include "replay/sum_tree.h"

namespace rl::replay {

class PrioritizedSampler final : public Sampler {
 public:
  /// Slots are 0 .. capacity-1. Throws std::invalid_argument when capacity < 1, alpha is not
  /// finite and >= 0, or epsilon is not finite and > 0.
  PrioritizedSampler(int64_t capacity, double alpha, double epsilon = 1e-6);

  /// Stores (priority + epsilon)^alpha, or (max_priority() + epsilon)^alpha when `priority` is
  /// not finite and > 0. An out-of-range slot is a caller bug and aborts (in every method taking
  /// a slot).
  void Insert(int64_t slot, double priority) override;
  /// Sets the priority of a stored slot to `priority`; ignores slots that hold no transition and
  /// priorities that are negative or not finite.
  void Update(int64_t slot, double priority) override;
  void Remove(int64_t slot) override;
  /// Stratified over out.size() equal segments of the total.
  void Sample(std::mt19937_64* rng, std::span<SampledItem> out) override;
  double Probability(int64_t slot) const override;
  double MinProbability() const override;
  int64_t size() const override { return size_; }
  int64_t memory_bytes() const override { return tree_.memory_bytes(); }
  /// The stored values of every slot, the largest priority seen, alpha and epsilon (a snapshot
  /// of other alpha or epsilon is refused: its values would mean other probabilities).
  void Save(const std::string& prefix, StateStream* out) const override;
  void Restore(const std::string& prefix, const StateView& in,
               std::span<const int64_t> insert_number) override;

  double alpha() const { return alpha_; }
  double epsilon() const { return epsilon_; }
  /// Largest positive priority seen so far (1 before any): what Insert() without a priority
  /// uses.
  double max_priority() const { return max_priority_; }

 private:
  // (priority + epsilon)^alpha, kept within [1e-200, 1e200].
  double Stored(double priority) const;
  // Takes a priority given by the caller into max_priority_.
  void See(double priority);

  SumTree tree_;  // by slot: the stored value, 0 when the slot holds no transition
  double alpha_;
  double epsilon_;
  double max_priority_ = 1.0;
  bool seen_priority_ = false;  // whether max_priority_ comes from a priority seen yet
  int64_t size_ = 0;
};

}  // namespace rl::replay
