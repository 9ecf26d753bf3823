// ReplayTable: the replay daemon's storage, a ring buffer of transitions with flat float
// observations.
//
// Transitions are stored contiguously, one array per field (obs and next_obs hold
// capacity * obs_size floats each), in slots 0 .. capacity-1 filled in insertion order. Once the
// table is full, every insert overwrites the oldest transition. Which stored transitions a batch
// is drawn from is decided by a Sampler (uniform by default).
//
// Memory: capacity * (8 * obs_size + 37) bytes with the uniform sampler, allocated when obs_size
// becomes known (from the options, or from the first batch).
//
// The table knows nothing about LCM: the caller hands it views of its own arrays. Not
// thread-safe: one thread inserts and samples.
#pragma once

#include <cstdint>
#include <memory>
#include <random>
#include <span>
#include <vector>

#include "replay/sampler.h"

namespace rl::replay {

struct ReplayTableOptions {
  // Transitions kept; when full, the oldest is overwritten.
  int64_t capacity = 100000;
  // Floats per observation; 0: taken from the first batch inserted. Batches of any other size
  // are refused.
  int obs_size = 0;

  /// Throws std::invalid_argument naming the field when a value is out of range.
  void Validate() const;
};

/// A batch of transitions to insert, as views of the caller's arrays. obs and next_obs hold
/// count * obs_size floats (transition i at [i*obs_size, (i+1)*obs_size)); action, reward and
/// discount hold count values; episode_id and priority hold count values or are empty (stored
/// as -1 and 0).
struct TransitionBatchView {
  int obs_size = 0;
  int count = 0;
  std::span<const float> obs;
  std::span<const float> next_obs;
  std::span<const int32_t> action;
  std::span<const float> reward;
  std::span<const float> discount;
  std::span<const int64_t> episode_id;
  std::span<const float> priority;
};

/// Where Sample() writes a batch of `count` transitions: obs and next_obs have room for
/// count * obs_size floats, the others for count values each; episode_id may be empty (not
/// wanted). `index` receives each transition's insert number (0 for the first transition ever
/// inserted, 1 for the next, ...; its slot is index % capacity), so that a later priority update
/// can tell a transition that has been overwritten since. `weight` receives the importance
/// weight (1 for uniform sampling).
struct SampleSpans {
  std::span<float> obs;
  std::span<float> next_obs;
  std::span<int32_t> action;
  std::span<float> reward;
  std::span<float> discount;
  std::span<int64_t> index;
  std::span<float> weight;
  std::span<int64_t> episode_id;
};

/// A batch that owns its arrays, for callers that have none of their own. Resize() allocates
/// only when the batch grows.
struct SampleBatch {
  int obs_size = 0;
  int count = 0;
  std::vector<float> obs;
  std::vector<float> next_obs;
  std::vector<int32_t> action;
  std::vector<float> reward;
  std::vector<float> discount;
  std::vector<int64_t> index;
  std::vector<float> weight;
  std::vector<int64_t> episode_id;

  void Resize(int new_count, int new_obs_size);
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
  /// an obs_size other than the table's, or views whose sizes do not match count and obs_size.
  /// Values are stored as they are: checking them (finite, discount in [0, 1]) is the caller's
  /// job. O(count * obs_size); allocates only on the first batch when obs_size was 0.
  [[nodiscard]] const char* Insert(const TransitionBatchView& batch);

  /// Draws batch_size transitions with replacement, as the sampler decides, into `out`, whose
  /// spans must have exactly the sizes batch_size and obs_size() call for (a mismatch is a
  /// caller bug and aborts). Returns false, writing nothing, when the table is empty.
  /// O(batch_size * obs_size); no allocation once a batch of this size has been drawn.
  bool Sample(int batch_size, std::mt19937_64* rng, const SampleSpans& out);

  /// Transitions stored (at most capacity()).
  int64_t size() const { return size_; }
  int64_t capacity() const { return options_.capacity; }
  /// Floats per observation; 0 until known.
  int obs_size() const { return obs_size_; }
  /// Transitions ever inserted (including overwritten ones).
  int64_t total_inserts() const { return total_inserts_; }
  /// Transitions ever drawn by Sample().
  int64_t total_samples() const { return total_samples_; }

 private:
  void Allocate(int obs_size);

  ReplayTableOptions options_;
  std::unique_ptr<Sampler> sampler_;
  int obs_size_ = 0;
  int64_t size_ = 0;
  int64_t total_inserts_ = 0;
  int64_t total_samples_ = 0;

  // Per-slot storage (obs_ and next_obs_: obs_size_ floats per slot).
  std::vector<float> obs_;
  std::vector<float> next_obs_;
  std::vector<int32_t> action_;
  std::vector<float> reward_;
  std::vector<float> discount_;
  std::vector<int64_t> episode_id_;
  std::vector<int64_t> insert_number_;

  std::vector<SampledItem> items_;  // scratch for Sample()
};

}  // namespace rl::replay
