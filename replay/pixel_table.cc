#include "replay/pixel_table.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <stdexcept>
#include <string>
#include <utility>

#include "common/check.h"
#include "replay/priorities.h"
#include "replay/uniform_sampler.h"

namespace rl::replay {
namespace {

constexpr int64_t kMaxCapacity = int64_t{1} << 40;
constexpr int kMaxSide = 4096;
constexpr int kMaxStack = 64;
constexpr int32_t kMaxActorId = 65535;
// Distinct actors whose frame ids are held (64 KiB each).
constexpr size_t kMaxActors = 1024;
// Local ids remembered per actor; a power of two.
constexpr int64_t kWindow = 4096;
// Stale draws for one element before Sample() sweeps every stale transition away.
constexpr int kMaxRedraws = 16;

// Entry of local frame id `id` in an actor's window (ids may be any int64).
size_t WindowEntry(int64_t id) {
  return static_cast<size_t>(static_cast<uint64_t>(id) & static_cast<uint64_t>(kWindow - 1));
}

}  // namespace

void PixelTableOptions::Validate() const {
  if (capacity < 1 || capacity > kMaxCapacity) {
    throw std::invalid_argument("pixel table: capacity must be in [1, 2^40], got " +
                                std::to_string(capacity));
  }
  if (frame_capacity < 0 || frame_capacity > kMaxCapacity) {
    throw std::invalid_argument(
        "pixel table: frame_capacity must be in [0, 2^40] (0: default), got " +
        std::to_string(frame_capacity));
  }
  if (height < 0 || height > kMaxSide || width < 0 || width > kMaxSide) {
    throw std::invalid_argument("pixel table: height and width must be in [0, " +
                                std::to_string(kMaxSide) + "] (0: from the first batch), got " +
                                std::to_string(height) + " x " + std::to_string(width));
  }
  if (action_width < 0 || action_width > TransitionColumns::kMaxActionWidth) {
    throw std::invalid_argument(
        "pixel table: action_width must be in [0, 64] (0: from the first "
        "batch), got " +
        std::to_string(action_width));
  }
  if (stack < 0 || stack > kMaxStack) {
    throw std::invalid_argument("pixel table: stack must be in [0, " + std::to_string(kMaxStack) +
                                "] (0: from the first batch), got " + std::to_string(stack));
  }
}

int64_t PixelTableOptions::frames_kept() const {
  return frame_capacity > 0 ? frame_capacity : capacity + capacity / 32 + 4096;
}

void PixelSampleBatch::Resize(int new_count, int new_height, int new_width, int new_stack,
                              int new_action_width) {
  count = new_count;
  action_width = new_action_width;
  height = new_height;
  width = new_width;
  stack = new_stack;
  const auto n = static_cast<size_t>(new_count);
  const size_t bytes = n * static_cast<size_t>(new_stack) * static_cast<size_t>(new_height) *
                       static_cast<size_t>(new_width);
  obs.resize(bytes);
  next_obs.resize(bytes);
  action.resize(n * static_cast<size_t>(new_action_width));
  reward.resize(n);
  discount.resize(n);
  index.resize(n);
  weight.resize(n);
}

PixelSampleSpans PixelSampleBatch::spans() {
  return PixelSampleSpans{obs, next_obs, {action, reward, discount, index, weight, {}}};
}

PixelTable::PixelTable(PixelTableOptions options, std::unique_ptr<Sampler> sampler)
    : options_(options), sampler_(std::move(sampler)) {
  options_.Validate();
  frame_capacity_ = options_.frames_kept();
  if (sampler_ == nullptr) sampler_ = std::make_unique<UniformSampler>(options_.capacity);
  if (options_.height > 0 && options_.width > 0 && options_.stack > 0) {
    Allocate(options_.height, options_.width, options_.stack);
  }
}

PixelTable::~PixelTable() = default;

void PixelTable::Allocate(int height, int width, int stack) {
  height_ = height;
  width_ = width;
  stack_ = stack;
  const auto slots = static_cast<size_t>(options_.capacity);
  frames_.assign(static_cast<size_t>(frame_capacity_) * static_cast<size_t>(height) *
                     static_cast<size_t>(width),
                 0);
  frame_refs_.assign(slots * 2 * static_cast<size_t>(stack), -1);
}

PixelTable::ActorFrames* PixelTable::FindOrAddActor(int32_t actor_id) {
  auto it = std::lower_bound(actors_.begin(), actors_.end(), actor_id,
                             [](const ActorFrames& a, int32_t id) { return a.actor_id < id; });
  if (it != actors_.end() && it->actor_id == actor_id) return &*it;
  if (actors_.size() >= kMaxActors) return nullptr;
  ActorFrames added;
  added.actor_id = actor_id;
  added.window.assign(static_cast<size_t>(kWindow), FrameRef{});
  return &*actors_.insert(it, std::move(added));
}

bool PixelTable::Resolve(const ActorFrames& actor, std::span<const int64_t> local,
                         int64_t* global) const {
  const int64_t oldest_stored = total_frames_ - frame_capacity_;
  for (size_t k = 0; k < local.size(); ++k) {
    const FrameRef& ref = actor.window[WindowEntry(local[k])];
    if (ref.global < 0 || ref.local_id != local[k] || ref.global < oldest_stored) return false;
    global[k] = ref.global;
  }
  return true;
}

bool PixelTable::Stale(int64_t slot) const {
  const size_t refs = 2 * static_cast<size_t>(stack_);
  const int64_t* first = frame_refs_.data() + static_cast<size_t>(slot) * refs;
  return *std::min_element(first, first + refs) < total_frames_ - frame_capacity_;
}

void PixelTable::Drop(int64_t slot) {
  int64_t& number = columns_.insert_numbers()[static_cast<size_t>(slot)];
  if (number < 0) return;
  number = -1;
  sampler_->Remove(slot);
  --size_;
}

void PixelTable::DropAllStale() {
  for (int64_t slot = 0; slot < options_.capacity; ++slot) {
    if (columns_.insert_numbers()[static_cast<size_t>(slot)] >= 0 && Stale(slot)) Drop(slot);
  }
}

const char* PixelTable::Insert(const PixelBatchView& batch) {
  // Check the whole batch before storing any of it.
  if (batch.actor_id < 0 || batch.actor_id > kMaxActorId) return "actor_id outside [0, 65535]";
  if (batch.num_frames < 0 || batch.count < 0) return "negative num_frames or count";
  if (batch.num_frames == 0 && batch.count == 0) return "empty batch";
  if (batch.height < 1 || batch.height > kMaxSide || batch.width < 1 || batch.width > kMaxSide) {
    return "height or width outside [1, 4096]";
  }
  if (batch.stack < 1 || batch.stack > kMaxStack) return "stack outside [1, 64]";
  // The table's geometry once known, else the configured parts of it.
  const int want_height = height_ > 0 ? height_ : options_.height;
  const int want_width = width_ > 0 ? width_ : options_.width;
  const int want_stack = stack_ > 0 ? stack_ : options_.stack;
  if ((want_height > 0 && batch.height != want_height) ||
      (want_width > 0 && batch.width != want_width) ||
      (want_stack > 0 && batch.stack != want_stack)) {
    return "height, width or stack differs from the table's";
  }
  const auto num_frames = static_cast<size_t>(batch.num_frames);
  const size_t frame_bytes = static_cast<size_t>(batch.height) * static_cast<size_t>(batch.width);
  if (batch.frame_id.size() != num_frames || batch.frames.size() != num_frames * frame_bytes) {
    return "frame_id size is not num_frames or frames size is not num_frames * height * width";
  }
  const auto n = static_cast<size_t>(batch.count);
  const auto stack = static_cast<size_t>(batch.stack);
  if (batch.obs_frames.size() != n * stack || batch.next_obs_frames.size() != n * stack) {
    return "obs_frames or next_obs_frames size is not count * stack";
  }
  // A frames-only batch says nothing about actions; one with transitions must fit the width.
  const int width = columns_.allocated() ? columns_.action_width() : options_.action_width;
  if (n > 0) {
    if (const char* why = TransitionColumns::Check(batch.columns, n, width)) return why;
  }
  for (size_t j = 1; j < num_frames; ++j) {
    if (batch.frame_id[j] <= batch.frame_id[j - 1]) return "frame ids not increasing";
  }
  ActorFrames* actor = FindOrAddActor(batch.actor_id);
  if (actor == nullptr) return "too many actors (1024 distinct actor ids at most)";
  if (height_ == 0) Allocate(batch.height, batch.width, batch.stack);
  if (n > 0 && !columns_.allocated()) {
    columns_.Allocate(options_.capacity, batch.columns.action_width);
  }

  // A batch starting at or below the actor's newest id comes from a restarted actor: forget
  // the old ids, so that none of them is taken for a new frame that never arrived.
  if (num_frames > 0 && actor->any && batch.frame_id[0] <= actor->last_id) {
    std::fill(actor->window.begin(), actor->window.end(), FrameRef{});
  }

  // Store the frames in the ring and map their ids to their global numbers.
  for (size_t j = 0; j < num_frames; ++j) {
    const int64_t global = total_frames_++;
    const auto at = static_cast<size_t>(global % frame_capacity_) * frame_bytes;
    std::memcpy(frames_.data() + at, batch.frames.data() + j * frame_bytes, frame_bytes);
    actor->window[WindowEntry(batch.frame_id[j])] = FrameRef{batch.frame_id[j], global};
  }
  if (num_frames > 0) {
    actor->last_id = batch.frame_id[num_frames - 1];
    actor->any = true;
  }

  // Store each transition whose frames are all there into the slot after the newest one.
  int64_t global[2 * kMaxStack];
  for (size_t i = 0; i < n; ++i) {
    if (!Resolve(*actor, batch.obs_frames.subspan(i * stack, stack), global) ||
        !Resolve(*actor, batch.next_obs_frames.subspan(i * stack, stack), global + stack)) {
      ++missing_frames_;
      continue;
    }
    const int64_t slot = total_inserts_ % options_.capacity;
    const auto s = static_cast<size_t>(slot);
    std::copy(global, global + 2 * stack, frame_refs_.data() + s * 2 * stack);
    if (columns_.insert_numbers()[s] < 0) ++size_;
    columns_.Store(s, batch.columns, i, total_inserts_);
    sampler_->Insert(slot, batch.columns.priority.empty() ? 0.0 : batch.columns.priority[i]);
    ++total_inserts_;
  }
  return nullptr;
}

bool PixelTable::Sample(int batch_size, std::mt19937_64* rng, const PixelSampleSpans& out) {
  RL_CHECK(batch_size > 0) << "batch_size must be positive, got " << batch_size;
  if (size_ == 0) return false;
  const auto n = static_cast<size_t>(batch_size);
  const auto stack = static_cast<size_t>(stack_);
  const size_t frame_bytes = static_cast<size_t>(height_) * static_cast<size_t>(width_);
  const size_t stack_bytes = stack * frame_bytes;
  RL_CHECK(out.obs.size() == n * stack_bytes && out.next_obs.size() == n * stack_bytes)
      << "obs and next_obs must hold batch_size * stack * height * width = " << n * stack_bytes
      << " bytes";
  RL_CHECK(columns_.Fits(out.columns, n))
      << "action must hold batch_size * action_width floats, reward, discount, index and weight "
         "batch_size = "
      << n << " values";

  // Let the sampler choose the slots, drawing again for each stale one (removed on the way).
  if (items_.size() < n) items_.resize(n);
  const std::span<SampledItem> items(items_.data(), n);
  sampler_->Sample(rng, items);
  bool dropped = false;
  for (size_t i = 0; i < n; ++i) {
    int redraws = 0;
    // A slot is drawn again if it is stale, or was dropped as stale earlier in this batch.
    while (columns_.insert_numbers()[static_cast<size_t>(items[i].slot)] < 0 ||
           Stale(items[i].slot)) {
      Drop(items[i].slot);
      dropped = true;
      ++stale_draws_;
      if (++redraws == kMaxRedraws) DropAllStale();
      if (size_ == 0) return false;
      sampler_->Sample(rng, items.subspan(i, 1));
    }
  }
  // Removals changed the probabilities: take every draw's from the final state, so that all of
  // them, and the minimum, are consistent.
  if (dropped) {
    for (SampledItem& item : items) item.probability = sampler_->Probability(item.slot);
  }

  // Rebuild the stacks from the frame ring and gather the other fields.
  const double min_probability = sampler_->MinProbability();
  for (size_t i = 0; i < n; ++i) {
    const auto s = static_cast<size_t>(items[i].slot);
    const int64_t* refs = frame_refs_.data() + s * 2 * stack;
    for (size_t k = 0; k < 2 * stack; ++k) {
      const uint8_t* frame =
          frames_.data() + static_cast<size_t>(refs[k] % frame_capacity_) * frame_bytes;
      uint8_t* to = k < stack ? out.obs.data() + i * stack_bytes + k * frame_bytes
                              : out.next_obs.data() + i * stack_bytes + (k - stack) * frame_bytes;
      std::memcpy(to, frame, frame_bytes);
    }
    columns_.Gather(s, i, out.columns);
    out.columns.weight[i] = ImportanceWeight(items[i].probability, min_probability, beta_);
  }
  total_samples_ += batch_size;
  return true;
}

int64_t PixelTable::UpdatePriorities(std::span<const int64_t> index,
                                     std::span<const float> priority) {
  return ApplyPriorities(index, priority, columns_.insert_numbers(), total_inserts_,
                         sampler_.get());
}

void PixelTable::set_importance_exponent(double beta) {
  if (!(beta >= 0.0 && beta <= 1.0)) {
    throw std::invalid_argument("pixel table: importance exponent must be in [0, 1], got " +
                                std::to_string(beta));
  }
  beta_ = beta;
}

int64_t PixelTable::memory_bytes() const {
  size_t bytes = frames_.capacity() + frame_refs_.capacity() * sizeof(int64_t) +
                 items_.capacity() * sizeof(SampledItem) + actors_.capacity() * sizeof(ActorFrames);
  for (const ActorFrames& actor : actors_) bytes += actor.window.capacity() * sizeof(FrameRef);
  return static_cast<int64_t>(bytes) + columns_.memory_bytes() + sampler_->memory_bytes();
}

}  // namespace rl::replay
