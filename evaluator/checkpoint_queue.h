// The checkpoints the learner announces on RL_CHECKPOINT that are waiting to be scored. Every
// announced path enters the evaluator here, before anything opens it.
#pragma once

#include <cstdint>
#include <map>
#include <optional>

#include "evaluator/eval_history.h"
#include "rlmsg/checkpoint_t.hpp"

namespace rl::evaluator {

/// The newest announced checkpoint that is not scored yet comes first: when checkpoints come
/// faster than they are scored, the older unscored ones are superseded. Up to `backlog_limit`
/// superseded ones wait in a backlog, to be scored later, newest first, when nothing newer
/// waits; the others are skipped (and counted). Not thread-safe.
class CheckpointQueue {
 public:
  /// What Offer() did with an announcement.
  enum class Outcome {
    kQueued,      // it is the pending checkpoint now (a pending older one was superseded)
    kDuplicate,   // scored already (in `history`), pending or in the backlog already: ignored
    kSuperseded,  // older than the pending one: into the backlog, or skipped
  };

  /// `history` (not owned; must outlive the queue) tells which checkpoints are scored.
  /// `backlog_limit` 0: every superseded checkpoint is skipped.
  explicit CheckpointQueue(const EvalHistory* history, int backlog_limit = 0)
      : history_(history), backlog_limit_(backlog_limit) {}

  Outcome Offer(const rlmsg::checkpoint_t& announced);
  /// Removes and returns the pending checkpoint, if any.
  std::optional<rlmsg::checkpoint_t> Take();
  /// Removes and returns the newest checkpoint of the backlog whose file is still there (the
  /// learner deletes old checkpoints: those are skipped), if any.
  std::optional<rlmsg::checkpoint_t> TakeFromBacklog();

  bool has_pending() const { return pending_.has_value(); }
  /// Superseded checkpoints waiting in the backlog.
  int backlog() const { return static_cast<int>(backlog_.size()); }
  /// Superseded checkpoints dropped unscored: the backlog was full (its oldest go first) or
  /// their file was gone by the time their turn came.
  int64_t skipped() const { return skipped_; }
  /// Announcements of checkpoints scored, pending or waiting already (by file name and update).
  int64_t duplicates() const { return duplicates_; }

 private:
  // Into the backlog, the oldest out (skipped) when it is over the limit.
  void Defer(const rlmsg::checkpoint_t& superseded);

  const EvalHistory* history_;
  int backlog_limit_;
  std::optional<rlmsg::checkpoint_t> pending_;
  std::multimap<int64_t, rlmsg::checkpoint_t> backlog_;  // by update
  int64_t skipped_ = 0;
  int64_t duplicates_ = 0;
};

}  // namespace rl::evaluator
