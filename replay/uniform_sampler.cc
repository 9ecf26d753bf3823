#include "replay/uniform_sampler.h"

#include <stdexcept>

#include "common/check.h"

namespace rl::replay {

UniformSampler::UniformSampler(int64_t capacity) {
  if (capacity < 1) throw std::invalid_argument("UniformSampler: capacity must be at least 1");
  present_.assign(static_cast<size_t>(capacity), 0);
  slots_.reserve(static_cast<size_t>(capacity));
}

void UniformSampler::Insert(int64_t slot, double /*priority*/) {
  RL_CHECK(slot >= 0 && slot < static_cast<int64_t>(present_.size()))
      << "slot " << slot << " outside [0, " << present_.size() << ")";
  // A replaced slot keeps its place in slots_: its new transition is just as likely.
  uint8_t& present = present_[static_cast<size_t>(slot)];
  if (present == 0) {
    present = 1;
    slots_.push_back(slot);
  }
}

void UniformSampler::Sample(std::mt19937_64* rng, std::span<SampledItem> out) {
  RL_CHECK(!slots_.empty()) << "Sample() called on an empty sampler";
  std::uniform_int_distribution<size_t> pick(0, slots_.size() - 1);
  const double probability = 1.0 / static_cast<double>(slots_.size());
  for (SampledItem& item : out) {
    item.slot = slots_[pick(*rng)];
    item.probability = probability;
  }
}

}  // namespace rl::replay
