// Small facts about processes, from /proc and wait statuses, that the launcher, its watchdog and
// `launch.sh --stop` share.
#pragma once

#include <sys/types.h>

#include <cstdint>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "launch/launch_options.h"

namespace rl::launch {

/// The start time of process `pid` (field 22 of /proc/PID/stat, in clock ticks since boot): with
/// the pid, it names one process, so that a pid since reused by another is not taken for it.
/// 0 when there is no such process or it has ended (a zombie).
uint64_t ProcessStartTime(pid_t pid);

/// Whether `pid` is the same living process that had `start_time` (ProcessStartTime).
bool SameProcessAlive(pid_t pid, uint64_t start_time);

/// "SIGSEGV" for 11; "SIG<n>" for a number without a name.
std::string SignalName(int signal);

/// How a process ended, from its wait status: "status 2", "signal 11 (SIGSEGV)".
std::string DescribeWaitStatus(int wait_status);

/// The exit code a shell would report for the wait status: the status, or 128 + the signal.
int ShellExitCode(int wait_status);

/// Whether the process `pid` has the file `path` open (its /proc/PID/fd links).
bool HoldsFileOpen(pid_t pid, const std::string& path);

/// Whether a TCP socket of this network namespace listens on `port` (/proc/net/tcp and tcp6).
bool ListensOnTcp(int port);

/// Files of one folder whose names a predicate accepts: how many, their total size, and the
/// largest one (name and size; -1 when there is none).
struct FolderFiles {
  int files = 0;
  int64_t bytes = 0;
  std::string largest;
  int64_t largest_bytes = -1;
};
FolderFiles LookInFolder(const std::string& dir,
                         const std::function<bool(const std::string& name)>& match);

/// A process being stopped, and when it may be killed. The rule, for the supervisor, its
/// destructor and the watchdog alike: not before RestartLimits::stop_seconds after `began`
/// (MonoSeconds() of its SIGTERM), and after that not while it is still writing in `dir`, the
/// folder where it writes files atomically as it stops (NAME.tmp.<pid>, renamed when complete: the
/// replay's last snapshot, the learner's state; "" for a process that writes nothing): while a
/// temporary file there appeared, grew or went within stop_stall_seconds, and until
/// stop_write_limit after `began`.
class StopWrites {
 public:
  StopWrites(std::string dir, double began, const RestartLimits& limits);
  /// Looks at the folder again (at most every 0.25 s) and returns whether the process is still
  /// writing at `now` (MonoSeconds()) by the rule above.
  bool Writing(double now);
  /// Whether it may be killed at `now`: stop_seconds have passed and it is not writing. Looks at
  /// the folder before the deadline too, so that a stall is timed from the last change seen.
  bool Overdue(double now) {
    const bool writing = Writing(now);
    return now >= deadline_ && !writing;
  }
  /// " (NAME: N MB so far)" for the largest temporary file, "" when there is none.
  std::string Describe() const;

 private:
  std::string dir_;
  double deadline_;  // began + stop_seconds
  double stall_;
  double end_;           // began + stop_write_limit
  FolderFiles seen_;     // the temporary files when it last looked
  double looked_ = -1;   // when it last looked
  double changed_ = -1;  // when it last saw a change (< 0: never)
};

/// The directory of the running executable (/proc/self/exe).
std::string ExecutableDir();

/// Runs `argv` (argv[0] a path), waits for it and returns its standard output; throws
/// std::runtime_error naming the program when it cannot run or exits other than with status 0
/// (with the last line of its standard error). For short queries (`PROGRAM --list-options`).
std::string RunAndCapture(const std::vector<std::string>& argv);

}  // namespace rl::launch
