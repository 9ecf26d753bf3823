// The run's training metrics as a time series: what every process publishes on RL_STATS_*, kept in
// the run folder as JSON lines (metrics.jsonl), one line per role and row.
//
//   {"t": 12.0, "role": "learner", "updates": 5000, "updates_per_second": 412.5, ...}
//
// Appending and crash-safe: each row (the lines of every role) is one write(2) to a file opened
// with O_APPEND, so a process killed at any moment leaves whole lines, and a restarted writer
// appends after them, its t carrying on from the last line's (last_t()), so that a resumed run's
// rows follow the earlier parts' instead of starting again at 0. Bounded for long runs: a row every
// second for the first hour, then every ten seconds (about 4,000 rows in the first hour and 360 an
// hour after that, per role).
#pragma once

#include <cstdint>
#include <string>

#include "rlmsg/stats_actor_t.hpp"
#include "rlmsg/stats_evaluator_t.hpp"
#include "rlmsg/stats_learner_t.hpp"
#include "rlmsg/stats_replay_t.hpp"

namespace rl::tools {

/// One JSON line (with its newline) for a row `t` seconds into the run of the newest stats message
/// of a process, received `age` seconds before the row (a row repeats the newest message, so a
/// process that went silent shows as a growing age, not as fresh figures). The role is the
/// message's sender ("actor-3", "replay", "learner", "evaluator").
std::string MetricsLine(double t, const rlmsg::stats_actor_t& s, double age = 0);
std::string MetricsLine(double t, const rlmsg::stats_replay_t& s, double age = 0);
std::string MetricsLine(double t, const rlmsg::stats_learner_t& s, double age = 0);
std::string MetricsLine(double t, const rlmsg::stats_evaluator_t& s, double age = 0);

/// The episodes that the actors of the metrics file at `path` ran, all their lives together: for
/// each actor role, the count of its last line plus the count before each drop (a restarted actor
/// counts from 0 again). 0 for a missing file; lines that are not JSON are passed over. A resumed
/// run's monitor starts its episode count from it.
int64_t ActorEpisodes(const std::string& path);

class MetricsLog {
 public:
  /// Opens `path` for appending (creating it), and reads the t of its last line (last_t()).
  /// Throws std::runtime_error naming the path. `dense_seconds` and the two periods set the row
  /// schedule (see the file comment).
  explicit MetricsLog(const std::string& path, double dense_seconds = 3600, double dense_period = 1,
                      double sparse_period = 10);
  MetricsLog(const MetricsLog&) = delete;
  MetricsLog& operator=(const MetricsLog&) = delete;
  ~MetricsLog();

  /// Whether a row is due `t` seconds into the run (true at t = 0, then on the schedule).
  bool Due(double t) const;
  /// Appends the lines of one row with one write and schedules the next row after `t`. Throws
  /// std::runtime_error on a write error.
  void AppendRow(double t, const std::string& lines);
  int64_t rows() const { return rows_; }
  /// The "t" of the file's last line when it was opened: 0 for a new or empty file. A writer of
  /// a resumed run adds it to its own clock. (Lines that are not JSON with a number t, such as a
  /// line cut short, are passed over.)
  double last_t() const { return last_t_; }

 private:
  std::string path_;
  int fd_ = -1;
  double dense_seconds_;
  double dense_period_;
  double sparse_period_;
  double next_ = 0;
  int64_t rows_ = 0;
  double last_t_ = 0;
};

}  // namespace rl::tools
