#include "replay/uniform_sampler.h"

#include <stdexcept>
#include <string>
#include <vector>

#include "common/check.h"
#include "common/state_file.h"

namespace rl::replay {

UniformSampler::UniformSampler(int64_t capacity) {
  if (capacity < 1) throw std::invalid_argument("UniformSampler: capacity must be at least 1");
  position_.assign(static_cast<size_t>(capacity), -1);
  slots_.reserve(static_cast<size_t>(capacity));
}

void UniformSampler::CheckSlot(int64_t slot) const {
  RL_CHECK(slot >= 0 && slot < static_cast<int64_t>(position_.size()))
      << "slot " << slot << " outside [0, " << position_.size() << ")";
}

void UniformSampler::Insert(int64_t slot, double /*priority*/) {
  CheckSlot(slot);
  // A replaced slot keeps its place in slots_: its new transition is just as likely.
  int64_t& position = position_[static_cast<size_t>(slot)];
  if (position < 0) {
    position = static_cast<int64_t>(slots_.size());
    slots_.push_back(slot);
  }
}

void UniformSampler::Remove(int64_t slot) {
  CheckSlot(slot);
  int64_t& position = position_[static_cast<size_t>(slot)];
  if (position < 0) return;
  // Move the last slot into the gap, so that slots_ stays dense.
  const int64_t last = slots_.back();
  slots_[static_cast<size_t>(position)] = last;
  position_[static_cast<size_t>(last)] = position;
  slots_.pop_back();
  position = -1;
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

double UniformSampler::Probability(int64_t slot) const {
  CheckSlot(slot);
  if (position_[static_cast<size_t>(slot)] < 0) return 0.0;
  return 1.0 / static_cast<double>(slots_.size());
}

double UniformSampler::MinProbability() const {
  return slots_.empty() ? 0.0 : 1.0 / static_cast<double>(slots_.size());
}

int64_t UniformSampler::memory_bytes() const {
  return static_cast<int64_t>((position_.capacity() + slots_.capacity()) * sizeof(int64_t));
}

}  // namespace rl::replay

namespace rl::replay {

void UniformSampler::Save(const std::string& prefix, StateStream* out) const {
  out->PutText(prefix + "kind", "uniform");
  out->AddInts(prefix + "slots", slots_);
}

void UniformSampler::Restore(const std::string& prefix, const StateView& in,
                             std::span<const int64_t> insert_number) {
  const auto capacity = static_cast<int64_t>(position_.size());
  RL_CHECK(static_cast<int64_t>(insert_number.size()) == capacity)
      << "insert_number must have one entry per slot";
  const std::string kind = in.Text(prefix + "kind");
  if (kind != "uniform") {
    throw std::runtime_error("the snapshot's sampler is " + kind + ", this replay's uniform");
  }
  const std::vector<int64_t> slots = in.Ints(prefix + "slots", capacity);
  // Every stored slot exactly once, and nothing else.
  std::vector<int64_t> position(static_cast<size_t>(capacity), -1);
  for (size_t i = 0; i < slots.size(); ++i) {
    const int64_t slot = slots[i];
    if (slot < 0 || slot >= capacity || position[static_cast<size_t>(slot)] >= 0 ||
        insert_number[static_cast<size_t>(slot)] < 0) {
      throw std::runtime_error("section '" + prefix +
                               "slots' names a slot out of range, twice, or without a transition");
    }
    position[static_cast<size_t>(slot)] = static_cast<int64_t>(i);
  }
  for (int64_t slot = 0; slot < capacity; ++slot) {
    if (insert_number[static_cast<size_t>(slot)] >= 0 && position[static_cast<size_t>(slot)] < 0) {
      throw std::runtime_error("section '" + prefix + "slots' misses a slot with a transition");
    }
  }
  position_ = std::move(position);
  slots_.assign(slots.begin(), slots.end());
  slots_.reserve(static_cast<size_t>(capacity));
}

}  // namespace rl::replay
