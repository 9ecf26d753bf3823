#include "replay/table.h"

#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>

#include "common/check.h"
#include "replay/uniform_sampler.h"

namespace rl::replay {

const char* TableKindName(TableKind kind) { return kind == TableKind::kPixels ? "pixels" : "flat"; }

Table::Table(int64_t capacity, std::unique_ptr<Sampler> sampler)
    : capacity_(capacity), sampler_(std::move(sampler)) {
  if (sampler_ == nullptr) sampler_ = std::make_unique<UniformSampler>(capacity_);
}

Table::~Table() = default;

void Table::set_importance_exponent(double beta) {
  if (!(beta >= 0.0 && beta <= 1.0)) {
    throw std::invalid_argument("replay table: importance exponent must be in [0, 1], got " +
                                std::to_string(beta));
  }
  beta_ = beta;
}

int64_t Table::UpdatePriorities(std::span<const int64_t> index, std::span<const float> priority) {
  RL_CHECK(index.size() == priority.size()) << "index and priority must have the same size, got "
                                            << index.size() << " and " << priority.size();
  const std::vector<int64_t>& insert_number = columns_.insert_numbers();
  int64_t applied = 0;
  for (size_t i = 0; i < index.size(); ++i) {
    // The slot must still hold that very transition: this rules out overwritten ones (the slot
    // holds a later insert), ones dropped as stale, and ones never inserted.
    const int64_t number = index[i];
    if (number < 0 || number >= total_inserts_) continue;
    const int64_t slot = number % capacity_;
    if (insert_number[static_cast<size_t>(slot)] != number) continue;
    if (!std::isfinite(priority[i]) || priority[i] < 0.0f) continue;
    sampler_->Update(slot, priority[i]);
    ++applied;
  }
  return applied;
}

size_t Table::Append(const ColumnsView& columns, size_t i) {
  const int64_t slot = total_inserts_ % capacity_;
  const auto s = static_cast<size_t>(slot);
  if (columns_.insert_numbers()[s] < 0) ++size_;
  columns_.Store(s, columns, i, total_inserts_);
  sampler_->Insert(slot, columns.priority.empty() ? 0.0 : columns.priority[i]);
  ++total_inserts_;
  return s;
}

std::span<SampledItem> Table::Draw(size_t n, std::mt19937_64* rng, const SampleSpans& out) {
  RL_CHECK(columns_.Fits(out.columns, n))
      << "action must hold batch_size * action_width floats, reward, discount, index and weight "
         "batch_size = "
      << n << " values, episode_id none or batch_size";
  if (items_.size() < n) items_.resize(n);
  const std::span<SampledItem> items(items_.data(), n);
  sampler_->Sample(rng, items);
  return items;
}

void Table::Gather(const SampledItem& item, size_t i, double min_probability,
                   const SampleSpans& out) const {
  columns_.Gather(static_cast<size_t>(item.slot), i, out.columns);
  out.columns.weight[i] = ImportanceWeight(item.probability, min_probability, beta_);
}

int64_t Table::common_memory_bytes() const {
  return static_cast<int64_t>(items_.capacity() * sizeof(SampledItem)) + columns_.memory_bytes() +
         sampler_->memory_bytes();
}

}  // namespace rl::replay
