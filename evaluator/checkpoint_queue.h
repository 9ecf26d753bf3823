// The checkpoints the learner announces on RL_CHECKPOINT that are waiting to be scored. Every
// announced path enters the evaluator here, before anything opens it.
#pragma once

#include <cstdint>
#include <optional>

#include "evaluator/eval_history.h"
#include "rlmsg/checkpoint_t.hpp"

namespace rl::evaluator {

/// Keeps only the newest announced checkpoint that is not scored yet: when checkpoints come
/// faster than they are scored, the older unscored ones are skipped (and counted). Not
/// thread-safe.
class CheckpointQueue {
 public:
  /// What Offer() did with an announcement.
  enum class Outcome {
    kQueued,     // it is the pending checkpoint now (a pending older one was skipped)
    kDuplicate,  // scored already (in `history`) or pending already: ignored
    kSkipped,    // older than the pending one: skipped
  };

  /// `history` (not owned; must outlive the queue) tells which checkpoints are scored.
  explicit CheckpointQueue(const EvalHistory* history) : history_(history) {}

  Outcome Offer(const rlmsg::checkpoint_t& announced);
  /// Removes and returns the pending checkpoint, if any.
  std::optional<rlmsg::checkpoint_t> Take();

  bool has_pending() const { return pending_.has_value(); }
  /// Announcements skipped for a newer one.
  int64_t skipped() const { return skipped_; }
  /// Announcements of checkpoints scored or pending already (by file name and update).
  int64_t duplicates() const { return duplicates_; }

 private:
  const EvalHistory* history_;
  std::optional<rlmsg::checkpoint_t> pending_;
  int64_t skipped_ = 0;
  int64_t duplicates_ = 0;
};

}  // namespace rl::evaluator
