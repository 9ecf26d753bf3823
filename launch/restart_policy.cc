#include "launch/restart_policy.h"

#include <sys/wait.h>

#include <algorithm>
#include <cmath>

namespace rl::launch {

ExitDecision RestartPolicy::OnExit(double run_seconds, int wait_status, bool ready) {
  ExitDecision d;
  const bool signaled = WIFSIGNALED(wait_status);
  if (!signaled && WEXITSTATUS(wait_status) == 0) {
    d.verdict = ExitVerdict::kFinished;
    return d;
  }
  if (!signaled && (!ready || run_seconds < limits_.startup_seconds)) {
    d.verdict = ExitVerdict::kStartupFailure;
    return d;
  }
  if (run_seconds >= limits_.reset_after) count_ = 0;
  if (count_ >= limits_.max_restarts) {
    d.verdict = ExitVerdict::kSpent;
    return d;
  }
  ++count_;
  d.verdict = ExitVerdict::kRestart;
  d.restart = count_;
  // 2^(k-1) without overflow: past 2^30 the cap has long been reached.
  d.delay = std::min(limits_.max_backoff,
                     limits_.first_backoff * std::ldexp(1.0, std::min(count_ - 1, 30)));
  return d;
}

double MonitorSilenceLimit(const RestartLimits& limits) {
  return limits.max_backoff + limits.ready_timeout + 5;
}

}  // namespace rl::launch
