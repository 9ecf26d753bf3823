// Table: the storage of a run's transitions as the replay service sees it, whatever their
// observations are. Two kinds implement it: ReplayTable (flat float observations,
// replay_table.h) and PixelTable (grayscale frames stored once, stacks rebuilt when sampled,
// pixel_table.h). The service makes one of them at its start, of the kind the env's static spec
// says, and uses it through this interface only.
//
// What every table keeps the same way lives here: the slots' common fields (TransitionColumns:
// action, reward, discount, episode id, insert number), the sampler that chooses which slots a
// batch is drawn from, the counters, the importance-sampling exponent and priority updates.
// Slots are filled in insertion order; once the table is full, every insert overwrites the
// oldest transition.
//
// Tables know nothing about LCM: the caller hands them views of its own arrays. Not
// thread-safe: one thread inserts and samples.
#pragma once

#include <cstdint>
#include <memory>
#include <random>
#include <span>
#include <string>
#include <vector>

#include "replay/sampler.h"
#include "replay/transition_columns.h"

namespace rl::replay {

/// The kinds of table, and the name of each in snapshots ("flat", "pixels").
enum class TableKind { kFlat, kPixels };
const char* TableKindName(TableKind kind);

/// A batch of transitions to insert, as views of the caller's arrays. `count` transitions whose
/// common fields are in `columns` (transition_columns.h), and their observations:
///   - flat batches (obs_size > 0): obs and next_obs hold count * obs_size floats (transition i
///     at [i * obs_size, (i + 1) * obs_size));
///   - pixel batches (obs_size 0), from actor `actor_id`: num_frames new frames of height *
///     width bytes with their local ids (strictly increasing), and each transition's obs and
///     next_obs stacks named by local frame id, oldest first (count * stack ids each, transition
///     i at [i * stack, (i + 1) * stack)); see pixel_table.h.
/// Values are not checked here (finite, discount in [0, 1], actions in range): that is the
/// caller's job.
struct TransitionBatchView {
  int obs_size = 0;
  int count = 0;
  std::span<const float> obs;
  std::span<const float> next_obs;
  ColumnsView columns;
  int32_t actor_id = 0;
  int height = 0;
  int width = 0;
  int stack = 0;
  int num_frames = 0;
  std::span<const int64_t> frame_id;
  std::span<const uint8_t> frames;
  std::span<const int64_t> obs_frames;
  std::span<const int64_t> next_obs_frames;
};

/// What a sampled transition's observations are: obs_size floats (flat tables), or stack frames
/// of height * width bytes (pixel tables); 0 until the table knows.
struct ObservationShape {
  int obs_size = 0;
  int height = 0;
  int width = 0;
  int stack = 0;

  /// Bytes of one stack of frames.
  int64_t pixel_bytes() const { return int64_t{stack} * height * width; }
  /// Whether the table knows its observations yet.
  bool known() const { return obs_size > 0 || pixel_bytes() > 0; }
};

/// Where Sample() writes a batch of `count` transitions. Flat tables: obs and next_obs have room
/// for count * obs_size floats; pixel tables: obs_pixels and next_obs_pixels for count * stack *
/// height * width bytes (transition i's stack at [i * stack * height * width, ...), its frames
/// oldest first); the spans of the other kind are empty. The other fields as ColumnSpans says.
/// `index` receives each transition's insert number (0 for the first transition ever inserted,
/// 1 for the next, ...; its slot is index % capacity), so that a later priority update can tell
/// a transition that has been overwritten since. `weight` receives the importance weight (see
/// Table::set_importance_exponent; 1 for uniform sampling).
struct SampleSpans {
  std::span<float> obs;
  std::span<float> next_obs;
  ColumnSpans columns;
  std::span<uint8_t> obs_pixels;
  std::span<uint8_t> next_obs_pixels;
};

class Table {
 public:
  Table(const Table&) = delete;
  Table& operator=(const Table&) = delete;
  virtual ~Table();

  virtual TableKind kind() const = 0;

  /// Stores the batch's transitions (and frames), overwriting the oldest when full. Returns
  /// nullptr on success, or a short reason why the whole batch was refused (nothing stored):
  /// a batch of the other kind, a shape other than the table's, views whose sizes do not match
  /// the counts (and, per kind, what its header says).
  [[nodiscard]] virtual const char* Insert(const TransitionBatchView& batch) = 0;

  /// Draws batch_size transitions with replacement, as the sampler decides, into `out`, whose
  /// spans must have exactly the sizes batch_size and shape() call for (a mismatch is a caller
  /// bug and aborts). Each weight is (N * P(i))^-beta / max_j (N * P(j))^-beta, the maximum
  /// taken over all N stored transitions, so weights are at most 1; with the uniform sampler
  /// they are exactly 1. Returns false, writing nothing, when the table holds no transition that
  /// can be drawn. No allocation once a batch of this size has been drawn.
  virtual bool Sample(int batch_size, std::mt19937_64* rng, const SampleSpans& out) = 0;

  /// What a sample's observations are.
  virtual ObservationShape shape() const = 0;

  /// The exponent beta of the importance weights, in [0, 1] (throws std::invalid_argument
  /// otherwise): 0 turns the correction off (weights 1), 1 (the default) fully compensates the
  /// non-uniform probabilities. Schaul et al. anneal it from about 0.4 to 1 over training.
  void set_importance_exponent(double beta);
  double importance_exponent() const { return beta_; }

  /// Gives transition index[i] (an insert number, as Sample() reports it) the priority
  /// priority[i] (|TD error|), for every i. Entries are skipped when their transition is not
  /// stored: overwritten since, removed (pixel tables: stale), or never inserted (index < 0 or
  /// >= total_inserts()); and when the priority is negative or not finite. Returns the number of
  /// entries applied. index and priority must have the same size (a mismatch is a caller bug and
  /// aborts). O(n log capacity).
  int64_t UpdatePriorities(std::span<const int64_t> index, std::span<const float> priority);

  /// Transitions stored that can be drawn (at most capacity()).
  int64_t size() const { return size_; }
  int64_t capacity() const { return capacity_; }
  /// Transitions ever inserted (including overwritten ones).
  int64_t total_inserts() const { return total_inserts_; }
  /// Transitions ever drawn by Sample().
  int64_t total_samples() const { return total_samples_; }
  /// Floats per action; 0 until known.
  int action_width() const { return columns_.action_width(); }
  /// Bytes held by the table and its sampler (the capacities of their arrays).
  virtual int64_t memory_bytes() const = 0;
  /// The sampler, for inspection (probabilities, size).
  const Sampler& sampler() const { return *sampler_; }

  /// Frames ever stored, frames kept, transitions skipped because a frame they name was missing,
  /// and draws made again because a frame had been overwritten: 0 for tables without frames.
  virtual int64_t total_frames() const { return 0; }
  virtual int64_t frame_capacity() const { return 0; }
  virtual int64_t transitions_missing_frames() const { return 0; }
  virtual int64_t stale_draws() const { return 0; }
  /// Whether nothing was ever stored (no transition, no frame).
  bool unused() const { return total_inserts_ == 0 && total_frames() == 0; }

  /// Adds the table (shape, counters, every slot, the sampler's state) to a snapshot as
  /// sections prefix + "...", referring to its arrays: the table must not change until the
  /// snapshot is written (a fork()ed child writes a copy-on-write image of it).
  virtual void Save(const std::string& prefix, StateStream* out) const = 0;
  /// Replaces the table's contents by a snapshot's. Throws std::runtime_error saying why it is
  /// refused: another capacity, a shape or action width other than the configured ones, or
  /// contents that are not a table's. Every length is checked against the configuration before
  /// anything is allocated. A table whose Restore threw must not be used further.
  virtual void Restore(const std::string& prefix, const StateView& in) = 0;

 protected:
  /// A null sampler means uniform; a sampler given must have `capacity` slots (capacity >= 1).
  Table(int64_t capacity, std::unique_ptr<Sampler> sampler);

  /// Stores element i of `columns` in the next slot (the oldest is overwritten) with the next
  /// insert number, and gives it to the sampler. Returns the slot.
  size_t Append(const ColumnsView& columns, size_t i);
  /// Checks that `out` fits a batch of n (aborts otherwise) and lets the sampler draw n slots.
  std::span<SampledItem> Draw(size_t n, std::mt19937_64* rng, const SampleSpans& out);
  /// Writes the common fields of item i's slot, with its importance weight, into `out`.
  void Gather(const SampledItem& item, size_t i, double min_probability,
              const SampleSpans& out) const;
  /// Bytes of the columns, the sampler and the draws' scratch.
  int64_t common_memory_bytes() const;

  int64_t capacity_;
  std::unique_ptr<Sampler> sampler_;
  int64_t size_ = 0;
  int64_t total_inserts_ = 0;
  int64_t total_samples_ = 0;
  double beta_ = 1.0;
  // Insert numbers of -1 mark slots that hold no transition that can be drawn.
  TransitionColumns columns_;
  std::vector<SampledItem> items_;  // scratch for Sample()
};

}  // namespace rl::replay
