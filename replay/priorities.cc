#include "replay/priorities.h"

#include <cmath>

#include "common/check.h"

namespace rl::replay {

int64_t ApplyPriorities(std::span<const int64_t> index, std::span<const float> priority,
                        std::span<const int64_t> insert_number, int64_t total_inserts,
                        Sampler* sampler) {
  RL_CHECK(index.size() == priority.size()) << "index and priority must have the same size, got "
                                            << index.size() << " and " << priority.size();
  const auto capacity = static_cast<int64_t>(insert_number.size());
  int64_t applied = 0;
  for (size_t i = 0; i < index.size(); ++i) {
    // The slot must still hold that very transition: this rules out overwritten ones (the slot
    // holds a later insert), ones dropped as stale, and ones never inserted.
    const int64_t number = index[i];
    if (number < 0 || number >= total_inserts) continue;
    const int64_t slot = number % capacity;
    if (insert_number[static_cast<size_t>(slot)] != number) continue;
    if (!std::isfinite(priority[i]) || priority[i] < 0.0f) continue;
    sampler->Update(slot, priority[i]);
    ++applied;
  }
  return applied;
}

}  // namespace rl::replay
