// TransitionColumns: the per-transition fields that both replay tables store slot by slot —
// the action (action_width floats), reward, discount, episode id and insert number — with the
// checks and copies of them written once. The tables add their observations (float vectors, or
// frame references) beside it.
//
// Memory: slots * (4 * action_width + 24) bytes. Not thread-safe.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "common/state_fwd.h"

namespace rl::replay {

/// The per-transition fields of a batch to insert, as views of the caller's arrays: count
/// transitions, action holds count * action_width floats (transition i at [i * action_width,
/// (i + 1) * action_width)), reward and discount count values, episode_id and priority count
/// values or empty (stored as -1, and "priority not known").
struct ColumnsView {
  int action_width = 0;
  std::span<const float> action;
  std::span<const float> reward;
  std::span<const float> discount;
  std::span<const int64_t> episode_id;
  std::span<const float> priority;
};

/// Where a sample's per-transition fields go: action has room for count * action_width floats,
/// the others for count values each (episode_id may be empty: not wanted).
struct ColumnSpans {
  std::span<float> action;
  std::span<float> reward;
  std::span<float> discount;
  std::span<int64_t> index;
  std::span<float> weight;
  std::span<int64_t> episode_id;
};

class TransitionColumns {
 public:
  /// Widest action stored (floats).
  static constexpr int kMaxActionWidth = 64;

  /// Why the view cannot hold `count` transitions for a table whose action width is
  /// `table_width` (0: not known yet), or nullptr.
  static const char* Check(const ColumnsView& view, size_t count, int table_width);

  /// Sizes every column for `slots` transitions of `action_width` floats; every slot empty.
  void Allocate(int64_t slots, int action_width);
  bool allocated() const { return action_width_ > 0; }
  int action_width() const { return action_width_; }

  /// Stores transition i of `view` in `slot` with insert number `number`.
  void Store(size_t slot, const ColumnsView& view, size_t i, int64_t number);
  /// Writes the fields of `slot` as element i of `out` (index: the insert number).
  void Gather(size_t slot, size_t i, const ColumnSpans& out) const;
  /// Whether `out` has the sizes a sample of `count` transitions needs.
  bool Fits(const ColumnSpans& out, size_t count) const;

  /// Insert number of each slot; -1 for a slot that holds no transition that can be drawn.
  std::vector<int64_t>& insert_numbers() { return insert_number_; }
  const std::vector<int64_t>& insert_numbers() const { return insert_number_; }

  int64_t memory_bytes() const;

  /// Adds the columns to a snapshot as sections prefix + "action", "reward", "discount",
  /// "episode_id", "insert_number", referring to them (they must stay unchanged until the
  /// snapshot is written). Empty sections when not allocated.
  void Save(const std::string& prefix, StateStream* out) const;
  /// Allocates `slots` slots of `action_width` floats (0: none, the columns stay unallocated
  /// and the sections must be empty) and fills them from a snapshot. Throws std::runtime_error
  /// naming a section of another length; the values themselves are the table's to check.
  void Restore(const std::string& prefix, const StateView& in, int64_t slots, int action_width);

 private:
  int action_width_ = 0;
  std::vector<float> action_;
  std::vector<float> reward_;
  std::vector<float> discount_;
  std::vector<int64_t> episode_id_;
  std::vector<int64_t> insert_number_;
};

}  // namespace rl::replay
