// The slots a sampler draws, for the sampler tests.
#pragma once

#include <cstdint>
#include <random>
#include <vector>

#include "replay/sampler.h"

namespace rl::replay {

/// The slots of `count` draws from `sampler` with a generator seeded with `seed`, in draw order.
inline std::vector<int64_t> DrawSlots(Sampler* sampler, int count, uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::vector<SampledItem> items(static_cast<size_t>(count));
  sampler->Sample(&rng, items);
  std::vector<int64_t> slots;
  for (const SampledItem& item : items) slots.push_back(item.slot);
  return slots;
}

}  // namespace rl::replay
