// ReplayTable: the Table (table.h) of transitions with flat float observations.
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

#include "replay/table.h"

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

class ReplayTable final : public Table {
 public:
  /// Throws std::invalid_argument when the options are bad. A null sampler means uniform.
  explicit ReplayTable(ReplayTableOptions options, std::unique_ptr<Sampler> sampler = nullptr);
  ~ReplayTable() override;

  TableKind kind() const override { return TableKind::kFlat; }

  /// Stores every transition of the batch, overwriting the oldest ones when full. Refuses (see
  /// Table::Insert) a pixel batch (obs_size 0), an obs_size or action width other than the
  /// table's, or views whose sizes do not match count, obs_size and action_width.
  /// O(count * obs_size); allocates only on the first batch when obs_size was 0.
  [[nodiscard]] const char* Insert(const TransitionBatchView& batch) override;

  /// As Table::Sample(); returns false only when the table is empty.
  /// O(batch_size * (obs_size + log capacity)).
  bool Sample(int batch_size, std::mt19937_64* rng, const SampleSpans& out) override;

  ObservationShape shape() const override { return {obs_size_, 0, 0, 0}; }
  /// Floats per observation; 0 until known.
  int obs_size() const { return obs_size_; }
  int64_t memory_bytes() const override;

  /// O(1) besides the section entries.
  void Save(const std::string& prefix, StateStream* out) const override;
  /// O(capacity * obs_size); allocates what the configured capacity and the snapshot's checked
  /// shape need.
  void Restore(const std::string& prefix, const StateView& in) override;

 private:
  void Allocate(int obs_size, int action_width);

  ReplayTableOptions options_;
  int obs_size_ = 0;

  // Per-slot storage (obs_size_ floats per slot).
  std::vector<float> obs_;
  std::vector<float> next_obs_;
};

}  // namespace rl::replay
