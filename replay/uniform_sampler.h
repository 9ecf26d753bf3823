// UniformSampler: every stored slot is drawn with the same probability 1/size().
#pragma once

#include <cstdint>
#include <random>
#include <span>
#include <vector>

#include "replay/sampler.h"

namespace rl::replay {

class UniformSampler final : public Sampler {
 public:
  /// Slots are 0 .. capacity-1. Throws std::invalid_argument when capacity < 1. Memory:
  /// 16 bytes per slot.
  explicit UniformSampler(int64_t capacity);

  /// O(1). Throws nothing; an out-of-range slot is a caller bug and aborts (as in every method
  /// taking a slot).
  void Insert(int64_t slot, double priority) override;
  /// O(1).
  void Remove(int64_t slot) override;
  /// O(out.size()), no allocation.
  void Sample(std::mt19937_64* rng, std::span<SampledItem> out) override;
  /// 1/size() for a stored slot, else 0. O(1).
  double Probability(int64_t slot) const override;
  /// 1/size() (0 when empty). O(1).
  double MinProbability() const override;
  int64_t size() const override { return static_cast<int64_t>(slots_.size()); }
  int64_t memory_bytes() const override;
  /// The stored slots in their order (so that a restored sampler draws the same slots).
  void Save(const std::string& prefix, StateStream* out) const override;
  void Restore(const std::string& prefix, const StateView& in,
               std::span<const int64_t> insert_number) override;

 private:
  void CheckSlot(int64_t slot) const;

  std::vector<int64_t> position_;  // by slot: its index in slots_, or -1 when it holds nothing
  // The slots that hold a transition, in order of first insertion, except that Remove() moves
  // the last one into the gap it leaves.
  std::vector<int64_t> slots_;
};

}  // namespace rl::replay
