#include "replay/replay_table.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>

#include "common/check.h"
#include "common/state_file.h"

namespace rl::replay {
namespace {

// Largest observation we accept (floats); far above any flat or pixel observation we use.
constexpr int kMaxObsSize = 1 << 24;

// Copies n values from `from` to `to`.
template <class T>
void CopyN(const T* from, size_t n, T* to) {
  std::copy(from, from + n, to);
}

// Validated options, so that the base is built from a checked capacity.
ReplayTableOptions Checked(ReplayTableOptions options) {
  options.Validate();
  return options;
}

}  // namespace

void ReplayTableOptions::Validate() const {
  if (capacity < 1) {
    throw std::invalid_argument("replay table: capacity must be at least 1, got " +
                                std::to_string(capacity));
  }
  if (action_width < 0 || action_width > TransitionColumns::kMaxActionWidth) {
    throw std::invalid_argument(
        "replay table: action_width must be in [0, 64] (0: from the "
        "first batch), got " +
        std::to_string(action_width));
  }
  if (obs_size < 0 || obs_size > kMaxObsSize) {
    throw std::invalid_argument("replay table: obs_size must be in [0, " +
                                std::to_string(kMaxObsSize) + "] (0: from the first batch), got " +
                                std::to_string(obs_size));
  }
}

void SampleBatch::Resize(int new_count, int new_obs_size, int new_action_width) {
  count = new_count;
  obs_size = new_obs_size;
  action_width = new_action_width;
  const auto n = static_cast<size_t>(new_count);
  const size_t values = n * static_cast<size_t>(new_obs_size);
  obs.resize(values);
  next_obs.resize(values);
  action.resize(n * static_cast<size_t>(new_action_width));
  reward.resize(n);
  discount.resize(n);
  index.resize(n);
  weight.resize(n);
  episode_id.resize(n);
}

SampleSpans SampleBatch::spans() {
  return SampleSpans{obs, next_obs, {action, reward, discount, index, weight, episode_id}, {}, {}};
}

ReplayTable::ReplayTable(ReplayTableOptions options, std::unique_ptr<Sampler> sampler)
    : Table(Checked(options).capacity, std::move(sampler)), options_(options) {
  obs_size_ = options_.obs_size;
  if (options_.obs_size > 0 && options_.action_width > 0) {
    Allocate(options_.obs_size, options_.action_width);
  }
}

ReplayTable::~ReplayTable() = default;

void ReplayTable::Allocate(int obs_size, int action_width) {
  obs_size_ = obs_size;
  const auto slots = static_cast<size_t>(options_.capacity);
  obs_.assign(slots * static_cast<size_t>(obs_size), 0.0f);
  next_obs_.assign(slots * static_cast<size_t>(obs_size), 0.0f);
  columns_.Allocate(options_.capacity, action_width);
}

const char* ReplayTable::Insert(const TransitionBatchView& batch) {
  // Check the whole batch before storing any of it.
  if (batch.obs_size == 0) return "a pixel batch (obs_size 0); this run stores flat transitions";
  if (batch.count <= 0) return "empty batch";
  if (batch.obs_size < 0 || batch.obs_size > kMaxObsSize) return "obs_size out of range";
  if (obs_size_ != 0 && batch.obs_size != obs_size_) return "obs_size differs from the table's";
  const auto n = static_cast<size_t>(batch.count);
  const size_t values = n * static_cast<size_t>(batch.obs_size);
  if (batch.obs.size() != values || batch.next_obs.size() != values) {
    return "obs or next_obs size is not count * obs_size";
  }
  const int width = columns_.allocated() ? columns_.action_width() : options_.action_width;
  if (const char* why = TransitionColumns::Check(batch.columns, n, width)) return why;
  if (!columns_.allocated()) Allocate(batch.obs_size, batch.columns.action_width);

  // Write each transition into the slot after the newest one, wrapping around.
  const auto obs_size = static_cast<size_t>(obs_size_);
  for (size_t i = 0; i < n; ++i) {
    const size_t s = Append(batch.columns, i);
    CopyN(batch.obs.data() + i * obs_size, obs_size, obs_.data() + s * obs_size);
    CopyN(batch.next_obs.data() + i * obs_size, obs_size, next_obs_.data() + s * obs_size);
  }
  return nullptr;
}

bool ReplayTable::Sample(int batch_size, std::mt19937_64* rng, const SampleSpans& out) {
  RL_CHECK(batch_size > 0) << "batch_size must be positive, got " << batch_size;
  if (size_ == 0) return false;
  const auto n = static_cast<size_t>(batch_size);
  const auto obs_size = static_cast<size_t>(obs_size_);
  RL_CHECK(out.obs.size() == n * obs_size && out.next_obs.size() == n * obs_size)
      << "obs and next_obs must hold batch_size * obs_size = " << n * obs_size << " floats";
  // Let the sampler choose the slots, then gather their fields.
  const std::span<SampledItem> items = Draw(n, rng, out);
  const double min_probability = sampler_->MinProbability();
  for (size_t i = 0; i < n; ++i) {
    const auto s = static_cast<size_t>(items[i].slot);
    RL_DCHECK(items[i].slot >= 0 && items[i].slot < size_) << "sampler chose an empty slot";
    CopyN(obs_.data() + s * obs_size, obs_size, out.obs.data() + i * obs_size);
    CopyN(next_obs_.data() + s * obs_size, obs_size, out.next_obs.data() + i * obs_size);
    Gather(items[i], i, min_probability, out);
  }
  total_samples_ += batch_size;
  return true;
}

void ReplayTable::Save(const std::string& prefix, StateStream* out) const {
  // An unallocated table (nothing inserted yet) has shape 0 whatever was configured.
  const int64_t shape[] = {options_.capacity, columns_.allocated() ? obs_size_ : 0,
                           columns_.action_width()};
  const int64_t counts[] = {size_, total_inserts_, total_samples_};
  out->PutInts(prefix + "shape", shape);
  out->PutInts(prefix + "counts", counts);
  out->AddFloats(prefix + "obs", obs_);
  out->AddFloats(prefix + "next_obs", next_obs_);
  columns_.Save(prefix, out);
  sampler_->Save(prefix + "sampler.", out);
}

void ReplayTable::Restore(const std::string& prefix, const StateView& in) {
  int64_t shape[3] = {};
  int64_t counts[3] = {};
  in.Copy<int64_t>(prefix + "shape", shape);
  in.Copy<int64_t>(prefix + "counts", counts);
  const int64_t capacity = shape[0];
  const int64_t obs_size = shape[1];
  const int64_t width = shape[2];
  const auto refuse = [](const std::string& why) { throw std::runtime_error(why); };
  if (capacity != options_.capacity) {
    refuse("the snapshot's table has capacity " + std::to_string(capacity) + ", this replay's " +
           std::to_string(options_.capacity));
  }
  if (obs_size < 0 || obs_size > kMaxObsSize || width < 0 ||
      width > TransitionColumns::kMaxActionWidth || (obs_size == 0) != (width == 0)) {
    refuse("the snapshot's table has a bad shape");
  }
  if (width > 0 && ((options_.obs_size > 0 && obs_size != options_.obs_size) ||
                    (options_.action_width > 0 && width != options_.action_width))) {
    refuse("the snapshot's transitions have obs_size " + std::to_string(obs_size) +
           " and action width " + std::to_string(width) + ", this replay's " +
           std::to_string(options_.obs_size) + " and " + std::to_string(options_.action_width));
  }
  const int64_t size = counts[0];
  const int64_t inserts = counts[1];
  const int64_t samples = counts[2];
  // (Counts stay far from overflow: 2^62 is ages of any run.)
  constexpr int64_t kMaxCount = int64_t{1} << 62;
  if (inserts < 0 || samples < 0 || inserts > kMaxCount || samples > kMaxCount ||
      size != std::min(inserts, capacity) || (width == 0 && inserts > 0)) {
    refuse("the snapshot's table counters are inconsistent");
  }

  // The arrays, sized from the configuration and the shape once the file is known to hold them.
  const int64_t floats = in.Count<float>(prefix + "obs");
  if (obs_size == 0 ? floats != 0 : floats % obs_size != 0 || floats / obs_size != capacity) {
    refuse("section '" + prefix + "obs' does not hold capacity * obs_size floats");
  }
  if (width > 0) {
    Allocate(static_cast<int>(obs_size), static_cast<int>(width));
  } else {
    obs_.clear();
    next_obs_.clear();
    obs_size_ = options_.obs_size;
  }
  in.Copy<float>(prefix + "obs", obs_);
  in.Copy<float>(prefix + "next_obs", next_obs_);
  columns_.Restore(prefix, in, capacity, static_cast<int>(width));
  size_ = size;
  total_inserts_ = inserts;
  total_samples_ = samples;

  // Slot s holds the newest insert number n < total_inserts with n % capacity == s.
  std::vector<int64_t> numbers(static_cast<size_t>(capacity), -1);
  for (int64_t slot = 0; slot < size; ++slot) {
    numbers[static_cast<size_t>(slot)] = slot + (inserts - 1 - slot) / capacity * capacity;
  }
  if (width > 0 && columns_.insert_numbers() != numbers) {
    refuse("the snapshot's insert numbers are not a table's");
  }
  sampler_->Restore(prefix + "sampler.", in, numbers);
}

int64_t ReplayTable::memory_bytes() const {
  const size_t bytes = (obs_.capacity() + next_obs_.capacity()) * sizeof(float);
  return static_cast<int64_t>(bytes) + common_memory_bytes();
}

}  // namespace rl::replay
