// Snapshotter: writes a process's state to a file periodically, in a fork()ed child, as Redis's
// BGSAVE does. The parent's pause is building the section list (the state is referred to, not
// copied) and fork() itself, which copies the page tables (figures in replay/README.md,
// Snapshots); the child sees a copy-on-write image of the state at that instant,
// writes it with StateStream (common/state_file.h) to a temporary file, fsyncs it and renames it
// over the snapshot file (AtomicFileStream, common/atomic_file.h), then _exits. A crash at any
// moment leaves the previous snapshot or the new one, whole.
//
// The child only makes system calls: no allocation, no lock, no stdio, no exception, since
// the parent has other threads (LCM's receive threads) that may hold a lock at the fork. It dies
// with its parent (PR_SET_PDEATHSIG), so a restarted process never races a stale writer, and
// runs at a lower priority (nice + 10) than the process that serves. At most one child runs at
// a time; the parent reaps it without blocking (waitpid WNOHANG) in Tick(), and logs and counts
// each snapshot: written or failed, bytes, pause, write time.
//
// Not thread-safe: one thread constructs the snapshotter and calls every method.
#pragma once

#include <sys/types.h>

#include <cstdint>
#include <functional>
#include <memory>
#include <string>

#include "common/atomic_file.h"
#include "common/state_file.h"

namespace rl::replay {

struct SnapshotterOptions {
  // The snapshot file; empty: no snapshots.
  std::string path;
  // Seconds between the starts of two snapshots (finite, > 0). After a crash at most the work
  // of this long (plus one write) is lost.
  double every_seconds = 60.0;
  // Log lines start with this ("replay").
  std::string program = "replay";

  /// Throws std::invalid_argument naming the field when a value is out of range.
  void Validate() const;
};

/// What the snapshots so far cost and gave.
struct SnapshotStats {
  int64_t written = 0;  // snapshots committed
  int64_t failed = 0;   // snapshots whose child failed (the previous file is kept)
  int64_t last_bytes = 0;
  double last_pause_seconds = 0.0;  // building the sections + fork(), in the parent
  double max_pause_seconds = 0.0;
  double last_fork_seconds = 0.0;   // fork() alone
  double last_write_seconds = 0.0;  // the child's write, fsync and rename
};

class Snapshotter {
 public:
  /// Removes temporary files that writers of an earlier process left (PATH.tmp.<pid>).
  /// `fill` adds the state to a StateStream of `kind` and returns a one-line summary of it for
  /// the log; `version` says whether the state changed (a snapshot is skipped while it returns
  /// what it returned at the last one). Throws std::invalid_argument when the options are bad.
  Snapshotter(SnapshotterOptions options, std::string kind,
              std::function<std::string(StateStream*)> fill, std::function<int64_t()> version);
  Snapshotter(const Snapshotter&) = delete;
  Snapshotter& operator=(const Snapshotter&) = delete;
  /// Waits for a running child (it finishes its snapshot).
  ~Snapshotter();

  /// Reaps a finished child, and starts the next snapshot when it is due (every_seconds after
  /// the start of the last one, the first every_seconds after `now` of the first call), no
  /// child runs and the state changed. `now`: monotonic seconds. Returns whether a child was
  /// started. Pauses the caller for the fork only.
  bool Tick(double now);
  /// Starts a snapshot now unless a child runs (then false). For tests and benchmarks.
  bool StartNow();
  /// Blocks until the running child (if any) has finished, and reaps it.
  void Wait();
  /// At the end: waits for the running child, then writes the state in this process when it
  /// changed since the last snapshot (blocking). Returns false when a write failed.
  bool Finish();

  bool running() const { return child_ > 0; }
  const SnapshotStats& stats() const { return stats_; }
  const SnapshotterOptions& options() const { return options_; }

 private:
  // Handles a reaped child's status and report.
  void Reaped(int status);
  // Removes temporary files of writers that died with an earlier process.
  void RemoveStaleTemporaries() const;

  SnapshotterOptions options_;
  std::string kind_;
  std::function<std::string(StateStream*)> fill_;
  std::function<int64_t()> version_;
  // The running child's stream and file (kept until it is reaped), pid, pipe and summary.
  std::unique_ptr<StateStream> stream_;
  std::unique_ptr<AtomicFileStream> file_;
  pid_t child_ = -1;
  int pipe_ = -1;
  std::string summary_;
  int64_t child_version_ = 0;
  double started_ = 0.0;  // monotonic seconds of the last start
  double next_ = -1.0;    // when the next snapshot is due (< 0: not yet set)
  int64_t written_version_ = 0;
  bool any_written_ = false;
  SnapshotStats stats_;
};

}  // namespace rl::replay
