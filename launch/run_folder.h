// A run folder on disk: creating it so that no two launches share one, its lock, the header of
// its config.ini (what --resume and the tests read), its key, and launch.pid (what --stop reads).
#pragma once

#include <sys/types.h>

#include <cstdint>
#include <optional>
#include <string>

namespace rl::launch {

/// The '# ...' lines at the top of RUN/config.ini, above the copy of the preset:
///   # Run of preset 'cartpole', started 2026-11-22T10:15:00+00:00
///   # run-id = 123
///   # lcm-url = udpm://239.255.76.67:P?ttl=0&recv_buf_size=4194304
///   # lcm-bulk-url = udpm://239.255.76.67:P+1?...
///   # lcm-samples-url = udpm://239.255.76.67:P+2?...   (not in runs of earlier versions)
///   # actors = 4 (of 4), seed = 1, goal = 475, time budget = 600 s
///   # extra: actor [...] replay [...] learner [...] evaluator [...]     (only with extra args)
struct RunHeader {
  std::string preset;
  std::string started;  // ISO 8601, seconds
  int64_t run_id = 0;
  std::string lcm_url;
  std::string lcm_bulk_url;
  std::string lcm_samples_url;
  int actors = 0;
  int num_actors = 0;
  uint64_t seed = 0;
  std::string goal;
  double time_budget = 0;
  std::string extra;  // the text after "# extra: ", or empty

  /// The main port of lcm_url (0 when it has none).
  int Port() const;
};

/// The header's lines, each ending in a newline.
std::string FormatRunHeader(const RunHeader& header);

/// Reads the header from the text of a config.ini (the first line of each kind counts). Throws
/// LaunchError naming `path` when the preset name, run id, actors or seed are missing.
RunHeader ParseRunHeader(const std::string& config_text, const std::string& path);

/// The local time now, formatted by strftime(3) with `format`.
std::string LocalTimeNow(const char* format);

/// The local time as 2026-11-22T10:15:00+01:00 (as `date -Iseconds`).
std::string IsoNow();

/// Creates a new run folder and returns its absolute path. `path` itself when it can be created
/// (its parents too), or when it is an empty folder; otherwise, when `suffix_when_taken` (a
/// default name), the first of path-2, path-3, ... that mkdir() creates, so that two launches
/// never get the same folder, even in the same second. Throws LaunchError with one line ("cannot
/// create the run folder P: <reason>", or "P exists and is not empty") otherwise.
std::string CreateRunFolder(const std::string& path, bool suffix_when_taken);

/// An exclusive flock() on RUN/lock for the object's life (the file is opened close-on-exec, so
/// no process of the run holds it): one launcher per run folder. The kernel releases it however
/// the launcher ends.
class RunLock {
 public:
  /// Throws LaunchError "the run in DIR is going (launcher pid N); ..." when another launcher
  /// holds it, or when the lock file cannot be made.
  explicit RunLock(const std::string& run_dir);
  ~RunLock();
  RunLock(const RunLock&) = delete;
  RunLock& operator=(const RunLock&) = delete;

 private:
  int fd_ = -1;
};

/// Writes RUN/launch.pid: "PID START" of this process (START: ProcessStartTime).
void WriteLaunchPid(const std::string& run_dir);

/// The launcher of RUN/launch.pid when that very process is still running; nothing when the
/// file is missing, malformed or names a process that has ended (its pid maybe reused since).
std::optional<pid_t> RunningLauncher(const std::string& run_dir);

/// Writes RUN/key (32 random bytes, mode 600, atomically) unless it is there and not empty (a
/// resumed run keeps its key). Throws LaunchError when it cannot.
void EnsureKeyFile(const std::string& path);

/// A random run id (48 bits, at least 1).
int64_t RandomRunId();

}  // namespace rl::launch
