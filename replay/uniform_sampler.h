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
  /// Slots are 0 .. capacity-1. Throws std::invalid_argument when capacity < 1.
  explicit UniformSampler(int64_t capacity);

  /// O(1). Throws nothing; an out-of-range slot is a caller bug and aborts.
  void Insert(int64_t slot, double priority) override;
  /// O(out.size()), no allocation.
  void Sample(std::mt19937_64* rng, std::span<SampledItem> out) override;
  int64_t size() const override { return static_cast<int64_t>(slots_.size()); }

 private:
  std::vector<uint8_t> present_;  // by slot: 1 when the slot holds a transition
  std::vector<int64_t> slots_;    // the slots that hold one, in order of first insertion
};

}  // namespace rl::replay
