#include "replay/pixel_table.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <stdexcept>
#include <string>
#include <utility>

#include "common/check.h"
#include "common/state_file.h"

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

// Validated options, so that the base is built from a checked capacity.
PixelTableOptions Checked(PixelTableOptions options) {
  options.Validate();
  return options;
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

SampleSpans PixelSampleBatch::spans() {
  return SampleSpans{{}, {}, {action, reward, discount, index, weight, {}}, obs, next_obs};
}

PixelTable::PixelTable(PixelTableOptions options, std::unique_ptr<Sampler> sampler)
    : Table(Checked(options).capacity, std::move(sampler)), options_(options) {
  frame_capacity_ = options_.frames_kept();
  if (options_.height > 0 && options_.width > 0 && options_.stack > 0) {
    Allocate(options_.height, options_.width, options_.stack);
  }
}

PixelTable::~PixelTable() = default;

void PixelTable::Allocate(int height, int width, int stack) {
  shape_.height = height;
  shape_.width = width;
  shape_.stack = stack;
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
  const size_t refs = 2 * static_cast<size_t>(shape_.stack);
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

const char* PixelTable::Insert(const TransitionBatchView& batch) {
  // Check the whole batch before storing any of it.
  if (batch.obs_size != 0) return "a flat batch (obs_size > 0); this run stores pixel transitions";
  if (batch.actor_id < 0 || batch.actor_id > kMaxActorId) return "actor_id outside [0, 65535]";
  if (batch.num_frames < 0 || batch.count < 0) return "negative num_frames or count";
  if (batch.num_frames == 0 && batch.count == 0) return "empty batch";
  if (batch.height < 1 || batch.height > kMaxSide || batch.width < 1 || batch.width > kMaxSide) {
    return "height or width outside [1, 4096]";
  }
  if (batch.stack < 1 || batch.stack > kMaxStack) return "stack outside [1, 64]";
  // The table's geometry once known, else the configured parts of it.
  const int want_height = shape_.height > 0 ? shape_.height : options_.height;
  const int want_width = shape_.width > 0 ? shape_.width : options_.width;
  const int want_stack = shape_.stack > 0 ? shape_.stack : options_.stack;
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
  if (shape_.height == 0) Allocate(batch.height, batch.width, batch.stack);
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
    const size_t s = Append(batch.columns, i);
    std::copy(global, global + 2 * stack, frame_refs_.data() + s * 2 * stack);
  }
  return nullptr;
}

bool PixelTable::Sample(int batch_size, std::mt19937_64* rng, const SampleSpans& out) {
  RL_CHECK(batch_size > 0) << "batch_size must be positive, got " << batch_size;
  if (size_ == 0) return false;
  const auto n = static_cast<size_t>(batch_size);
  const auto stack = static_cast<size_t>(shape_.stack);
  const size_t frame_bytes = static_cast<size_t>(shape_.height) * static_cast<size_t>(shape_.width);
  const size_t stack_bytes = stack * frame_bytes;
  RL_CHECK(out.obs_pixels.size() == n * stack_bytes &&
           out.next_obs_pixels.size() == n * stack_bytes)
      << "obs_pixels and next_obs_pixels must hold batch_size * stack * height * width = "
      << n * stack_bytes << " bytes";

  // Let the sampler choose the slots, drawing again for each stale one (removed on the way).
  const std::span<SampledItem> items = Draw(n, rng, out);
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
      uint8_t* to = k < stack
                        ? out.obs_pixels.data() + i * stack_bytes + k * frame_bytes
                        : out.next_obs_pixels.data() + i * stack_bytes + (k - stack) * frame_bytes;
      std::memcpy(to, frame, frame_bytes);
    }
    Gather(items[i], i, min_probability, out);
  }
  total_samples_ += batch_size;
  return true;
}

int64_t PixelTable::memory_bytes() const {
  size_t bytes = frames_.capacity() + frame_refs_.capacity() * sizeof(int64_t) +
                 actors_.capacity() * sizeof(ActorFrames);
  for (const ActorFrames& actor : actors_) bytes += actor.window.capacity() * sizeof(FrameRef);
  return static_cast<int64_t>(bytes) + common_memory_bytes();
}

}  // namespace rl::replay

namespace rl::replay {

void PixelTable::Save(const std::string& prefix, StateStream* out) const {
  const int64_t shape[] = {options_.capacity, frame_capacity_, shape_.height,
                           shape_.width,      shape_.stack,    columns_.action_width()};
  const int64_t counts[] = {size_,         total_inserts_,  total_samples_,
                            total_frames_, missing_frames_, stale_draws_};
  out->PutInts(prefix + "shape", shape);
  out->PutInts(prefix + "counts", counts);
  out->AddBytes(prefix + "frames", frames_);
  out->AddInts(prefix + "frame_refs", frame_refs_);
  columns_.Save(prefix, out);
  // Per actor: id, newest local id, whether it has sent a frame; then all windows, in order
  // (a FrameRef is two int64: local id, global number).
  static_assert(sizeof(FrameRef) == 2 * sizeof(int64_t));
  std::vector<int64_t> actors;
  for (const ActorFrames& a : actors_) {
    actors.insert(actors.end(), {int64_t{a.actor_id}, a.last_id, int64_t{a.any ? 1 : 0}});
  }
  out->PutInts(prefix + "actors", actors);
  out->AddInts(prefix + "windows", {});
  for (const ActorFrames& a : actors_) {
    out->AddPiece(a.window.data(), a.window.size() * sizeof(FrameRef));
  }
  sampler_->Save(prefix + "sampler.", out);
}

void PixelTable::Restore(const std::string& prefix, const StateView& in) {
  int64_t shape[6] = {};
  int64_t counts[6] = {};
  in.Copy<int64_t>(prefix + "shape", shape);
  in.Copy<int64_t>(prefix + "counts", counts);
  const auto refuse = [](const std::string& why) { throw std::runtime_error(why); };
  const int64_t capacity = shape[0];
  if (capacity != options_.capacity || shape[1] != frame_capacity_) {
    refuse("the snapshot's pixel table has capacity " + std::to_string(capacity) +
           " and frame capacity " + std::to_string(shape[1]) + ", this replay's " +
           std::to_string(options_.capacity) + " and " + std::to_string(frame_capacity_));
  }
  const int64_t height = shape[2], width = shape[3], stack = shape[4], action_width = shape[5];
  const bool geometry = height > 0 || width > 0 || stack > 0;
  if (geometry && (height < 1 || height > kMaxSide || width < 1 || width > kMaxSide || stack < 1 ||
                   stack > kMaxStack)) {
    refuse("the snapshot's pixel table has a bad geometry");
  }
  if (geometry && ((options_.height > 0 && height != options_.height) ||
                   (options_.width > 0 && width != options_.width) ||
                   (options_.stack > 0 && stack != options_.stack))) {
    refuse("the snapshot's frames are " + std::to_string(height) + " x " + std::to_string(width) +
           " in stacks of " + std::to_string(stack) + ", this replay's " +
           std::to_string(options_.height) + " x " + std::to_string(options_.width) + " in " +
           std::to_string(options_.stack));
  }
  if (action_width < 0 || action_width > TransitionColumns::kMaxActionWidth ||
      (action_width > 0 && options_.action_width > 0 && action_width != options_.action_width)) {
    refuse("the snapshot's action width " + std::to_string(action_width) +
           " is not this replay's " + std::to_string(options_.action_width));
  }
  const int64_t size = counts[0], inserts = counts[1], samples = counts[2], frames = counts[3];
  // (Counts stay far from overflow: 2^62 is ages of any run.)
  constexpr int64_t kMaxCount = int64_t{1} << 62;
  const auto count_ok = [](int64_t n) { return n >= 0 && n <= kMaxCount; };
  if (size < 0 || size > capacity || !count_ok(inserts) || !count_ok(samples) ||
      !count_ok(frames) || !count_ok(counts[4]) || !count_ok(counts[5]) ||
      (inserts > 0 && (action_width == 0 || !geometry)) || (frames > 0 && !geometry)) {
    refuse("the snapshot's pixel table counters are inconsistent");
  }
  // The lengths of the large sections, before anything is allocated for them.
  const int64_t frame_bytes = height * width;
  const int64_t frame_section = in.Count<uint8_t>(prefix + "frames");
  const int64_t refs_section = in.Count<int64_t>(prefix + "frame_refs");
  const bool frames_fit =
      geometry ? frame_section % frame_bytes == 0 && frame_section / frame_bytes == frame_capacity_
               : frame_section == 0;
  const bool refs_fit =
      geometry ? refs_section % (2 * stack) == 0 && refs_section / (2 * stack) == capacity
               : refs_section == 0;
  if (!frames_fit || !refs_fit) {
    refuse("the snapshot's frame ring or frame references do not fit its geometry");
  }
  const std::vector<int64_t> actors = in.Ints(prefix + "actors", 3 * int64_t{kMaxActors});
  if (actors.size() % 3 != 0 || in.Count<int64_t>(prefix + "windows") !=
                                    static_cast<int64_t>(actors.size() / 3) * 2 * kWindow) {
    refuse("the snapshot's actor windows do not fit its actors");
  }

  // Storage.
  if (geometry) {
    Allocate(static_cast<int>(height), static_cast<int>(width), static_cast<int>(stack));
  } else {
    shape_ = {};
    frames_.clear();
    frame_refs_.clear();
  }
  in.Copy<uint8_t>(prefix + "frames", frames_);
  in.Copy<int64_t>(prefix + "frame_refs", frame_refs_);
  columns_.Restore(prefix, in, capacity, static_cast<int>(action_width));
  size_ = size;
  total_inserts_ = inserts;
  total_samples_ = samples;
  total_frames_ = frames;
  missing_frames_ = counts[4];
  stale_draws_ = counts[5];

  // Actors, in increasing id, with windows of frames received.
  std::vector<int64_t> windows(actors.size() / 3 * 2 * kWindow);
  in.Copy<int64_t>(prefix + "windows", windows);
  actors_.clear();
  for (size_t k = 0; k < actors.size() / 3; ++k) {
    ActorFrames a;
    const int64_t id = actors[3 * k];
    if (id < 0 || id > kMaxActorId || (k > 0 && id <= actors_.back().actor_id) ||
        (actors[3 * k + 2] != 0 && actors[3 * k + 2] != 1)) {
      refuse("the snapshot's actors are not in increasing id order, or out of range");
    }
    a.actor_id = static_cast<int32_t>(id);
    a.last_id = actors[3 * k + 1];
    a.any = actors[3 * k + 2] != 0;
    a.window.resize(static_cast<size_t>(kWindow));
    for (size_t e = 0; e < a.window.size(); ++e) {
      const int64_t* ref = windows.data() + (k * kWindow + e) * 2;
      if (ref[1] < -1 || ref[1] >= frames)
        refuse("the snapshot's actor windows name unknown frames");
      a.window[e] = FrameRef{ref[0], ref[1]};
    }
    actors_.push_back(std::move(a));
  }

  // Slots: a transition where the insert number is set (that of the slot, among the last
  // `capacity` inserts), naming frames received; none elsewhere.
  int64_t stored = 0;
  const std::vector<int64_t>& numbers = columns_.insert_numbers();
  for (size_t slot = 0; slot < numbers.size(); ++slot) {
    const int64_t n = numbers[slot];
    if (n < 0) continue;
    if (n >= inserts || n < inserts - capacity || n % capacity != static_cast<int64_t>(slot)) {
      refuse("the snapshot's insert numbers are not a table's");
    }
    const int64_t* refs = frame_refs_.data() + slot * 2 * static_cast<size_t>(shape_.stack);
    for (int64_t k = 0; k < 2 * shape_.stack; ++k) {
      if (refs[k] < 0 || refs[k] >= frames)
        refuse("the snapshot's transitions name unknown frames");
    }
    ++stored;
  }
  if (stored != size) refuse("the snapshot's pixel table size is not its number of transitions");
  if (numbers.empty()) {
    sampler_->Restore(prefix + "sampler.", in,
                      std::vector<int64_t>(static_cast<size_t>(capacity), -1));
  } else {
    sampler_->Restore(prefix + "sampler.", in, numbers);
  }
}

}  // namespace rl::replay
