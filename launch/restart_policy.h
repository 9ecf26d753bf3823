// What the launcher does when one of its processes exits while the run goes on: the decision
// alone, without clocks or processes (the supervisor feeds it times and wait statuses), so that
// it can be tested alone. One RestartPolicy per planned process, for the launcher's life.
#pragma once

#include "launch/launch_options.h"

namespace rl::launch {

enum class ExitVerdict {
  kFinished,        // exited with status 0: it ended its work (or was told to stop); left down
  kStartupFailure,  // an error status before it was ready or within startup_seconds of its start:
                    // it refuses its input (options, snapshot, state), so a restart cannot help
  kRestart,         // started again after `delay`
  kSpent,           // its restarts in a row are spent: down for good
};

struct ExitDecision {
  ExitVerdict verdict = ExitVerdict::kFinished;
  double delay = 0;  // kRestart: seconds to wait before the start
  int restart = 0;   // kRestart: which restart in the current count this is (1, 2, ...)
};

class RestartPolicy {
 public:
  explicit RestartPolicy(const RestartLimits& limits) : limits_(limits) {}

  /// A start `run_seconds` before its exit with `wait_status` (waitpid's); `ready` whether it had
  /// printed its readiness line. A process that ran limits.reset_after seconds or more starts a
  /// new count first. Restart k of a count waits first_backoff * 2^(k-1) seconds, at most
  /// max_backoff; after max_restarts restarts in a row the verdict is kSpent. A process killed by
  /// a signal is never a startup failure.
  ExitDecision OnExit(double run_seconds, int wait_status, bool ready);

  /// Restarts in the current count.
  int restarts() const { return count_; }

 private:
  RestartLimits limits_;
  int count_ = 0;
};

/// The monitor's silence limit (its --stale-seconds) for these limits: a process being
/// restarted is silent for at most the longest backoff plus its time to get ready (after which
/// the launcher stops the run itself), plus 5 s for its first stats; a longer silence means a
/// process that hangs.
double MonitorSilenceLimit(const RestartLimits& limits);

}  // namespace rl::launch
