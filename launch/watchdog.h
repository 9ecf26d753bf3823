// The last line of defence against processes outliving their launcher. Every process of a run
// gets SIGTERM when the launcher dies (PR_SET_PDEATHSIG, set by the supervisor), so that it
// writes its last snapshot or state and exits; the watchdog, a small process forked from the
// launcher before the run starts, SIGKILLs those still running RestartLimits::stop_seconds after
// the launcher is gone, whatever ended it (SIGKILL, a crash), unless they are still writing their
// last files (as the supervisor's own stop waits for them). It ignores SIGINT, SIGTERM and SIGHUP,
// so that a signal to the launcher's process group does not take it away too.
#pragma once

#include <sys/types.h>

#include <string>

#include "launch/launch_options.h"

namespace rl::launch {

class Watchdog {
 public:
  /// Forks the watchdog (twice, so that it is no child of the launcher: the launcher waits for
  /// its run's processes only). It holds no file of the launcher's but the read end of a pipe
  /// whose write end only the launcher holds; that pipe closing is its signal.
  explicit Watchdog(const RestartLimits& limits);
  /// Closes the pipe: the watchdog kills what still runs limits.stop_seconds later (or once its
  /// last files stop growing), and exits. After an orderly stop every process has been reaped, so
  /// it exits at once.
  ~Watchdog();
  Watchdog(const Watchdog&) = delete;
  Watchdog& operator=(const Watchdog&) = delete;

  /// A process the launcher has just started (and not yet reaped, so that its pid is its own);
  /// `writes_at_stop`: PlannedProcess::writes_at_stop.
  void Watch(pid_t pid, const std::string& role, const std::string& writes_at_stop);

 private:
  int fd_ = -1;
};

}  // namespace rl::launch
