// The launcher's supervisor: starts a run's planned processes where the placement says, each once
// the one before it is ready; restarts those that exit while the run goes on, as their
// RestartPolicy says; and stops them all when the run is over. It runs in the launcher itself:
// single-threaded, one poll() loop over a signalfd (SIGCHLD, SIGINT, SIGTERM, SIGHUP), the
// monitor's output pipe and its own deadlines; processes are fork()ed and exec()ed and reaped
// with waitpid().
//
// Readiness is read from the process's log from the offset where this start began, so that a
// line of an earlier start or launch never counts. A process that exits with an error before it
// is ready (or within a few seconds of its start) failed at its start: the run stops at once and
// the launcher shows its last log lines.
//
// Every process is started in the launcher's process group (a Ctrl-C in the terminal reaches all
// of them), with SIGHUP ignored (a hang-up is the launcher's to handle: it stops the run in order)
// and SIGTERM as its parent-death signal: should the launcher die, each gets SIGTERM and writes
// its last snapshot or state (and the Watchdog kills those that hang).
#pragma once

#include <sys/types.h>

#include <functional>
#include <string>
#include <vector>

#include "launch/placement.h"
#include "launch/restart_policy.h"
#include "launch/run_plan.h"

namespace rl::launch {

class Watchdog;

/// How a run ended, and the launcher's exit status for it.
enum class RunEnd {
  kGoalReached,  // the monitor saw an evaluation reach the goal: 0
  kNotReached,   // the monitor ended it otherwise (time budget, a silent process, killed): 1
  kProcessDown,  // an essential process down for good (restarts spent, or exited with 0): 1
  kFailed,       // a process failed at its start or was not ready in time: 2
  kHangUp,       // SIGHUP to the launcher (its terminal closed): 129
  kInterrupted,  // SIGINT or SIGTERM to the launcher (Ctrl-C, --stop): 130
};

/// The exit status of the launcher for `end`.
int ExitStatusOf(RunEnd end);

/// Blocks SIGCHLD, SIGTERM, SIGHUP and SIGINT (unless SIGINT is ignored, as in a job a shell
/// started in the background) and returns a signalfd for them (close-on-exec). Call once, before
/// starting the Watchdog and the Supervisor.
int BlockRunSignals();

class Supervisor {
 public:
  /// `plan`, `placement` and `watchdog` must outlive the supervisor; `signal_fd` is
  /// BlockRunSignals()'s.
  Supervisor(const RunPlan& plan, const Placement& placement, int signal_fd, Watchdog* watchdog);
  /// Stops every process still running (SIGTERM; SIGKILL after RestartLimits::stop_seconds, or
  /// later to one still writing its last files, as Run()'s stop does) and reaps it: an exception
  /// in the launcher leaves nothing behind and loses no snapshot being written.
  ~Supervisor();
  Supervisor(const Supervisor&) = delete;
  Supervisor& operator=(const Supervisor&) = delete;

  /// Called once, when every process that starts before the monitor is ready.
  void OnAllReady(std::function<void()> callback) { on_all_ready_ = std::move(callback); }

  /// Starts the run, supervises it until it is over, stops every process (SIGTERM to all;
  /// RestartLimits::stop_seconds later SIGKILL, except to a process still writing its last
  /// files, PlannedProcess::writes_at_stop; the recorder last, once what the others sent is
  /// written) and returns how the run ended.
  RunEnd Run();

 private:
  struct Proc;
  enum class Phase { kRunning, kStopping, kStoppingLast, kDone };

  void Start(Proc* p);
  void Reap();
  void OnExit(Proc* p, int wait_status);
  void CheckReadiness(Proc* p, double now);
  void StartNextInOrder();
  void BeginStop(RunEnd end);
  void AdvanceStop(double now);
  void ForwardShownOutput();
  void HandleSignals();
  double NextWakeup(double now) const;
  bool AnyRunning(bool last) const;
  // A line to the launcher's standard error and to `p`'s log.
  void Tell(Proc* p, const std::string& line);
  void Fail(Proc* p, const std::string& why);

  const RunPlan& plan_;
  const Placement& placement_;
  int signal_fd_;
  Watchdog* watchdog_;
  std::vector<Proc> procs_;
  std::function<void()> on_all_ready_;
  size_t next_ = 0;  // the next process to start in order
  Phase phase_ = Phase::kRunning;
  RunEnd end_ = RunEnd::kNotReached;
  double stop_began_ = 0;
  double stop_deadline_ = 0;
  double last_check_ = 0;
  int64_t recorded_bytes_ = -1;
  int steady_checks_ = 0;
  int shown_fd_ = -1;      // read end of the shown process's output pipe
  int shown_log_fd_ = -1;  // its log, written by the launcher
};

}  // namespace rl::launch
