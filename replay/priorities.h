// Priority updates shared by the flat and the pixel table.
#pragma once

#include <cstdint>
#include <span>

#include "replay/sampler.h"

namespace rl::replay {

/// Applies priority[i] to the transition the tables reported as index[i] (its insert number),
/// for tables that keep `insert_number` per slot (slot = number % capacity) and have seen
/// `total_inserts` transitions. An entry is skipped when its transition is gone (overwritten,
/// dropped as stale, or never inserted) or its priority is negative or not finite. Returns the
/// entries applied. index and priority must have the same size (a mismatch aborts).
int64_t ApplyPriorities(std::span<const int64_t> index, std::span<const float> priority,
                        std::span<const int64_t> insert_number, int64_t total_inserts,
                        Sampler* sampler);

}  // namespace rl::replay
