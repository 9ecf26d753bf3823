// ReplayTable: the replay daemon's storage, a ring buffer of transitions with flat float
// observations.
//
// Transitions are stored contiguously, one array per field (obs and next_obs hold
// capacity * obs_size floats each), in slots 0 .. capacity-1 filled in insertion order. Once the
// table is full, every insert overwrites the oldest transition. Which stored transitions a batch
// is drawn from is decided by a Sampler (uniform by default, or PrioritizedSampler), which also
// gives each draw's probability for the importance weights.
//
// Memory: capacity * (8 * obs_size + 4 * action_width + 24) bytes, allocated when obs_size and
// action_width become known (from the options, or from the first batch), plus the sampler's (16
// bytes per slot for the uniform sampler, 32 to 64 for the prioritized one, allocated by its
// constructor).
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

#include "replay/sampler.h"
#include "replay/transition_columns.h"

namespace rl::replay {

struct ReplayTableOptions {
  // Transitions kept; when full, the oldest is overwritten.
  int64_t capacity = 100000;
  // Floats per observation; 0: taken from the first batch inserted. Batches of any other size
  // are refused.
  int obs_size = 0;
  // Floats per action (the env's action width: 1 for a discrete env); 0: taken from the first
  // batch. Batches of any other width are refused.
  int action_width = 0;

  /// Throws std::invalid_argument naming the field when a value is out of range.
  void Validate() const;
};

/// A batch of transitions to insert, as views of the caller's arrays. obs and next_obs hold
/// count * obs_size floats (transition i at [i*obs_size, (i+1)*obs_size)); the other fields as
/// ColumnsView (transition_columns.h) says. Values are not checked here (finite, discount in
/// [0, 1], actions in range): that is the caller's job.
struct TransitionBatchView {
  int obs_size = 0;
  int count = 0;
  std::span<const float> obs;
  std::span<const float> next_obs;
  ColumnsView columns;
};

/// Where Sample() writes a batch of `count` transitions: obs and next_obs have room for
/// count * obs_size floats; the other fields as ColumnSpans says. `index` receives each
/// transition's insert number (0 for the first transition ever inserted, 1 for the next, ...;
/// its slot is index % capacity), so that a later priority update can tell a transition that
/// has been overwritten since. `weight` receives the importance weight (see
/// ReplayTable::set_importance_exponent; 1 for uniform sampling).
struct SampleSpans {
  std::span<float> obs;
  std::span<float> next_obs;
  ColumnSpans columns;
};

/// A batch that owns its arrays, for callers that have none of their own. Resize() allocates
/// only when the batch grows.
struct SampleBatch {
  int obs_size = 0;
  int action_width = 0;
  int count = 0;
  std::vector<float> obs;
  std::vector<float> next_obs;
  std::vector<float> action;
  std::vector<float> reward;
  std::vector<float> discount;
  std::vector<int64_t> index;
  std::vector<float> weight;
  std::vector<int64_t> episode_id;

  void Resize(int new_count, int new_obs_size, int new_action_width = 1);
  SampleSpans spans();
};

class ReplayTable {
 public:
  /// Throws std::invalid_argument when the options are bad. A null sampler means uniform.
  explicit ReplayTable(ReplayTableOptions options, std::unique_ptr<Sampler> sampler = nullptr);
  ReplayTable(const ReplayTable&) = delete;
  ReplayTable& operator=(const ReplayTable&) = delete;
  ~ReplayTable();

  /// Stores every transition of the batch, overwriting the oldest ones when full. Returns
  /// nullptr on success, or a short reason why the whole batch was refused (nothing stored):
  /// an obs_size or action width other than the table's, or views whose sizes do not match
  /// count, obs_size and action_width.
  /// Values are stored as they are: checking them (finite, discount in [0, 1]) is the caller's
  /// job. O(count * obs_size); allocates only on the first batch when obs_size was 0.
  [[nodiscard]] const char* Insert(const TransitionBatchView& batch);

  /// Draws batch_size transitions with replacement, as the sampler decides, into `out`, whose
  /// spans must have exactly the sizes batch_size and obs_size() call for (a mismatch is a
  /// caller bug and aborts). Each weight is (N * P(i))^-beta / max_j (N * P(j))^-beta, the
  /// maximum taken over all N stored transitions, so weights are at most 1; with the uniform
  /// sampler they are exactly 1. Returns false, writing nothing, when the table is empty.
  /// O(batch_size * (obs_size + log capacity)); no allocation once a batch of this size has been
  /// drawn.
  bool Sample(int batch_size, std::mt19937_64* rng, const SampleSpans& out);

  /// The exponent beta of the importance weights, in [0, 1] (throws std::invalid_argument
  /// otherwise): 0 turns the correction off (weights 1), 1 (the default) fully compensates the
  /// non-uniform probabilities. Schaul et al. anneal it from about 0.4 to 1 over training.
  void set_importance_exponent(double beta);
  double importance_exponent() const { return beta_; }

  /// Gives transition index[i] (an insert number, as Sample() reports it) the priority
  /// priority[i] (|TD error|), for every i. Entries are skipped when their transition is not
  /// stored: overwritten since (index < total_inserts() - capacity()) or never inserted (index
  /// < 0 or >= total_inserts()); and when the priority is negative or not finite. Returns the
  /// number of entries applied. index and priority must have the same size (a mismatch is a
  /// caller bug and aborts). O(n log capacity).
  int64_t UpdatePriorities(std::span<const int64_t> index, std::span<const float> priority);

  /// Transitions stored (at most capacity()).
  int64_t size() const { return size_; }
  int64_t capacity() const { return options_.capacity; }
  /// Floats per observation; 0 until known.
  int obs_size() const { return obs_size_; }
  /// Floats per action; 0 until known.
  int action_width() const { return columns_.action_width(); }
  /// Transitions ever inserted (including overwritten ones).
  int64_t total_inserts() const { return total_inserts_; }
  /// Transitions ever drawn by Sample().
  int64_t total_samples() const { return total_samples_; }
  /// Bytes held by the table and its sampler (the capacities of their arrays).
  int64_t memory_bytes() const;
  /// The sampler, for inspection (probabilities, size).
  const Sampler& sampler() const { return *sampler_; }

  /// Adds the table (shape, counters, every slot, the sampler's state) to a snapshot as sections
  /// prefix + "...", referring to its arrays: the table must not change until the snapshot is
  /// written (a fork()ed child writes a copy-on-write image of it). O(1) besides the section
  /// entries.
  void Save(const std::string& prefix, StateStream* out) const;
  /// Replaces the table's contents by a snapshot's. Throws std::runtime_error saying why it is
  /// refused: another capacity, an obs_size or action width other than the configured ones, or
  /// contents that are not a table's (counters, insert numbers or sampler state inconsistent).
  /// A table whose Restore threw must not be used further. O(capacity * obs_size); allocates
  /// what the configured capacity and the snapshot's checked shape need.
  void Restore(const std::string& prefix, const StateView& in);

 private:
  void Allocate(int obs_size, int action_width);

  ReplayTableOptions options_;
  std::unique_ptr<Sampler> sampler_;
  int obs_size_ = 0;
  int64_t size_ = 0;
  int64_t total_inserts_ = 0;
  int64_t total_samples_ = 0;
  double beta_ = 1.0;

  // Per-slot storage (obs_ and next_obs_: obs_size_ floats per slot).
  std::vector<float> obs_;
  std::vector<float> next_obs_;
  TransitionColumns columns_;

  std::vector<SampledItem> items_;  // scratch for Sample()
};

}  // namespace rl::replay
