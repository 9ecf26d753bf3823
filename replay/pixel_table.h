// PixelTable: the Table (table.h) of pixel transitions, where every frame is stored once and
// observations are stacks rebuilt from frame references when sampled.
//
// Consecutive transitions of an episode share all but one frame of their stacks (obs of step
// t+1 is next_obs of step t, which is obs of step t shifted by one frame), so storing stacks
// would cost 2 * stack frames per transition where one suffices. Actors therefore send each
// frame once, with an actor-local frame id (increasing per actor), and name a transition's obs
// and next_obs stacks by frame ids, oldest first. The actor repeats an episode's first frame to
// fill the stack at a reset, so the table never needs to know where episodes begin.
//
// Storage:
//   - a ring of frame_capacity frames (height * width bytes each, grayscale, row-major),
//     numbered globally in arrival order: frame g lives at g % frame_capacity and is still
//     stored while g >= total_frames() - frame_capacity;
//   - per actor, a ring of the last 4096 local ids mapped to global frame numbers (an entry
//     keeps its local id, so that an id 4096 older, or one never received, is not mistaken for
//     it): a transition may name only frames among its actor's last 4096;
//   - per transition slot (capacity slots, filled in insertion order, the oldest overwritten):
//     the global numbers of its 2 * stack frames, and the fields every table stores
//     (TransitionColumns: action, reward, discount, episode id and insert number).
//
// A transition is stored only if every frame it names is known and still stored; otherwise it
// is skipped (counted in transitions_missing_frames(): typically a lost frame message) and the
// rest of its batch is stored. A stored transition becomes stale when the frame ring overwrites
// its oldest frame (frame_capacity too small for the frames that arrive while it is kept);
// Sample() then removes it from the sampler and draws again (counted in stale_draws()).
//
// Memory: frame_capacity * height * width bytes (in transparent huge pages where the kernel
// offers them: huge_page_allocator.h) + capacity * (16 * stack + 4 * action_width + 24) bytes +
// 64 KiB
// per actor, allocated when the geometry becomes known (from the options, or the first batch),
// plus the sampler's (16 bytes per slot for the uniform sampler, 32 to 64 for the prioritized
// one). With the default frame_capacity (capacity * 1.03125 + 4096) and 84 x 84 stacks of 4, a
// transition costs about 1.03 frames (7277 bytes) + 92 bytes + the sampler's.
//
// The table knows nothing about LCM: the caller hands it views of its own arrays. Not
// thread-safe: one thread inserts and samples.
#pragma once

#include <cstdint>
#include <memory>
#include <random>
#include <span>
#include <string>
#include <vector>

#include "replay/huge_page_allocator.h"
#include "replay/table.h"

namespace rl::replay {

struct PixelTableOptions {
  // Transitions kept; when full, the oldest is overwritten.
  int64_t capacity = 100000;
  // Frames kept; when full, the oldest is overwritten. 0: capacity + capacity / 32 + 4096, enough
  // for one new frame per transition plus a reset frame per episode of 32 steps or more, and
  // the frames of transitions in flight. Envs with shorter episodes need more (e.g. Catch, 9
  // steps: capacity * 10 / 9); too few only shrinks the replay (stale_draws() counts it).
  int64_t frame_capacity = 0;
  // Frame height and width in pixels (at most 4096 each), and frames per observation (at most
  // 64); 0: taken from the first batch. Batches with other values are refused.
  int height = 0;
  int width = 0;
  int stack = 0;
  // Floats per action; 0: taken from the first batch with transitions.
  int action_width = 0;

  /// Throws std::invalid_argument naming the field when a value is out of range.
  void Validate() const;
  /// frame_capacity, or its default when 0.
  int64_t frames_kept() const;
};

/// A batch that owns its arrays, for callers that have none of their own. Resize() allocates
/// only when the batch grows.
struct PixelSampleBatch {
  int count = 0;
  int height = 0;
  int width = 0;
  int stack = 0;
  int action_width = 0;
  std::vector<uint8_t> obs;
  std::vector<uint8_t> next_obs;
  std::vector<float> action;
  std::vector<float> reward;
  std::vector<float> discount;
  std::vector<int64_t> index;
  std::vector<float> weight;

  void Resize(int new_count, int new_height, int new_width, int new_stack,
              int new_action_width = 1);
  SampleSpans spans();
};

class PixelTable final : public Table {
 public:
  /// Throws std::invalid_argument when the options are bad. A null sampler means uniform; a
  /// sampler given must have `capacity` slots.
  explicit PixelTable(PixelTableOptions options, std::unique_ptr<Sampler> sampler = nullptr);
  ~PixelTable() override;

  TableKind kind() const override { return TableKind::kPixels; }

  /// Stores the batch's frames, then each of its transitions whose frames are all known (see
  /// the top of the file), overwriting the oldest when full. Returns nullptr on success (even
  /// when some transitions were skipped), or a short reason why the whole batch was refused
  /// (nothing stored): a flat batch (obs_size > 0), actor_id outside [0, 65535], a geometry
  /// other than the table's or out of range, views whose sizes do not match the counts, frame
  /// ids not strictly increasing within the batch, no frames and no transitions, or a 1025th
  /// distinct actor. A batch whose first frame id is not above the last one of its actor is
  /// taken to come from a restarted actor: the ids of its earlier frames are forgotten.
  /// O(num_frames * height * width + count * stack); allocates only for the first batch (when
  /// the geometry was not configured) and for the first batch of each actor.
  [[nodiscard]] const char* Insert(const TransitionBatchView& batch) override;

  /// As Table::Sample(), into obs_pixels and next_obs_pixels. A drawn transition that has
  /// become stale is removed from the sampler and the element is drawn again (without
  /// stratification); after 16 stale draws for one element, every stale transition is removed
  /// in one pass over the table (O(capacity * stack)), so the next draw is fresh. Returns
  /// false, writing nothing, when the table holds no transition that can be drawn.
  /// O(batch_size * (stack * height * width + log capacity)).
  bool Sample(int batch_size, std::mt19937_64* rng, const SampleSpans& out) override;

  ObservationShape shape() const override { return shape_; }
  /// Frame geometry; 0 until known.
  int height() const { return shape_.height; }
  int width() const { return shape_.width; }
  int stack() const { return shape_.stack; }

  /// Frames kept (the effective frame_capacity).
  int64_t frame_capacity() const override { return frame_capacity_; }
  /// Frames ever stored (including overwritten ones).
  int64_t total_frames() const override { return total_frames_; }
  /// Transitions skipped at Insert() because a frame they name is unknown or overwritten.
  int64_t transitions_missing_frames() const override { return missing_frames_; }
  /// Draws made again because the drawn transition's oldest frame had been overwritten.
  int64_t stale_draws() const override { return stale_draws_; }
  int64_t memory_bytes() const override;

  /// Adds the geometry, counters, the frame ring, every slot, each actor's window of frame ids
  /// and the sampler's state. O(actors) besides the section entries.
  void Save(const std::string& prefix, StateStream* out) const override;
  /// Also refused: another frame capacity, frame references or actor windows inconsistent.
  /// O(frame bytes + capacity * stack + actors * 4096).
  void Restore(const std::string& prefix, const StateView& in) override;

 private:
  // Where an actor's recent local frame ids are: entry local_id % kWindow.
  struct FrameRef {
    int64_t local_id = 0;
    int64_t global = -1;  // -1: empty
  };
  struct ActorFrames {
    int32_t actor_id = 0;
    int64_t last_id = 0;  // local id of its newest frame, when any
    bool any = false;     // whether a frame has been received
    std::vector<FrameRef> window;
  };

  void Allocate(int height, int width, int stack);
  // The actor's frames, or nullptr when it has none and no more actors can be held.
  ActorFrames* FindOrAddActor(int32_t actor_id);
  // Global frame numbers of `local` in *global; false when one is unknown or overwritten.
  bool Resolve(const ActorFrames& actor, std::span<const int64_t> local, int64_t* global) const;
  // Whether the slot's oldest frame has been overwritten.
  bool Stale(int64_t slot) const;
  // Takes a transition out of the table and its sampler.
  void Drop(int64_t slot);
  // Drops every stored transition that is stale.
  void DropAllStale();

  PixelTableOptions options_;
  int64_t frame_capacity_ = 0;
  ObservationShape shape_;  // the frames' geometry (obs_size 0); 0 until known
  int64_t total_frames_ = 0;
  int64_t missing_frames_ = 0;
  int64_t stale_draws_ = 0;

  // frame_capacity_ frames of height * width bytes, in huge pages where the kernel offers them
  std::vector<uint8_t, HugePageAllocator<uint8_t>> frames_;
  std::vector<ActorFrames> actors_;  // sorted by actor_id

  // Per-slot storage (frame_refs_: 2 * stack global frame numbers per slot, obs then next_obs).
  std::vector<int64_t> frame_refs_;
};

}  // namespace rl::replay
