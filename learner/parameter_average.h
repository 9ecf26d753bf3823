// An exponential moving average of a network's parameters (Polyak averaging of the iterates,
// as in Polyak and Juditsky 1992, and the "EMA of weights" of many deep-learning recipes): the
// learner's checkpoints may hold it instead of the current parameters, so that what is scored
// is the policy of the last few thousand updates rather than of the last one.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "common/state_file.h"

namespace rl::learner {

class ParameterAverage {
 public:
  /// Averages over about `horizon` (>= 1) updates: the plain mean of the first `horizon`
  /// parameter vectors added, then an exponential moving average with weight 1 / horizon.
  explicit ParameterAverage(int horizon);

  /// Mixes in the parameters after one more update. A vector of another length than the
  /// average's starts the average again from it.
  void Add(std::span<const float> params);

  /// The average; empty before the first Add.
  const std::vector<float>& values() const { return values_; }
  /// Vectors mixed in so far, counted up to the horizon.
  int64_t count() const { return count_; }

  /// Sections "<name>" and "<name>_count" of a learner state; Load reads them when they are
  /// there (a state saved without an average leaves this one empty) and throws
  /// std::runtime_error when the saved average is not `size` long.
  void Save(StateFile* state, const std::string& name) const;
  void Load(const StateFile& state, const std::string& name, int64_t size);

 private:
  int horizon_;
  std::vector<float> values_;
  int64_t count_ = 0;
};

}  // namespace rl::learner
