#include "launch/restart_policy.h"

#include <sys/wait.h>

#include <algorithm>
#include <csignal>

#include <gtest/gtest.h>

namespace rl::launch {
namespace {

// Wait statuses as waitpid() gives them.
int Exited(int code) { return code << 8; }
int Killed(int signal) { return signal; }

TEST(RestartPolicyTest, WaitStatusesAreBuiltAsWaitpidGivesThem) {
  EXPECT_TRUE(WIFEXITED(Exited(2)));
  EXPECT_EQ(WEXITSTATUS(Exited(2)), 2);
  EXPECT_TRUE(WIFSIGNALED(Killed(SIGKILL)));
  EXPECT_EQ(WTERMSIG(Killed(SIGKILL)), SIGKILL);
}

TEST(RestartPolicyTest, BackoffDoublesUpToItsCapThenTheRestartsAreSpent) {
  RestartLimits limits;
  limits.max_restarts = 6;
  limits.first_backoff = 1;
  limits.max_backoff = 10;
  RestartPolicy policy(limits);
  const double expected[] = {1, 2, 4, 8, 10, 10};
  for (int k = 0; k < 6; ++k) {
    const ExitDecision d = policy.OnExit(/*run_seconds=*/20, Killed(SIGSEGV), /*ready=*/true);
    ASSERT_EQ(d.verdict, ExitVerdict::kRestart) << k;
    EXPECT_EQ(d.restart, k + 1);
    EXPECT_DOUBLE_EQ(d.delay, expected[k]) << k;
  }
  EXPECT_EQ(policy.OnExit(20, Killed(SIGSEGV), true).verdict, ExitVerdict::kSpent);
  EXPECT_EQ(policy.restarts(), 6);
}

TEST(RestartPolicyTest, AProcessThatRanLongEnoughEarnsItsCountBack) {
  RestartLimits limits;
  limits.max_restarts = 2;
  limits.reset_after = 300;
  RestartPolicy policy(limits);
  EXPECT_EQ(policy.OnExit(10, Killed(SIGKILL), true).restart, 1);
  EXPECT_EQ(policy.OnExit(10, Killed(SIGKILL), true).restart, 2);
  // A crash after a day of running is the first of a new count, with the first backoff.
  const ExitDecision d = policy.OnExit(86400, Killed(SIGSEGV), true);
  EXPECT_EQ(d.verdict, ExitVerdict::kRestart);
  EXPECT_EQ(d.restart, 1);
  EXPECT_DOUBLE_EQ(d.delay, limits.first_backoff);
  // Crashes far apart never spend the restarts, however many.
  for (int k = 0; k < 100; ++k) {
    EXPECT_EQ(policy.OnExit(400, Killed(SIGSEGV), true).verdict, ExitVerdict::kRestart);
  }
}

TEST(RestartPolicyTest, AnErrorBeforeReadinessOrSoonAfterTheStartIsAStartupFailure) {
  RestartLimits limits;
  RestartPolicy policy(limits);
  // A snapshot refused after 8 s of loading: never ready.
  EXPECT_EQ(policy.OnExit(8, Exited(2), /*ready=*/false).verdict, ExitVerdict::kStartupFailure);
  // Ready, but failed within startup_seconds.
  EXPECT_EQ(policy.OnExit(1, Exited(1), /*ready=*/true).verdict, ExitVerdict::kStartupFailure);
  // A signal is never a startup failure, and an error later in the run is a crash.
  EXPECT_EQ(policy.OnExit(1, Killed(SIGKILL), false).verdict, ExitVerdict::kRestart);
  EXPECT_EQ(policy.OnExit(60, Exited(1), true).verdict, ExitVerdict::kRestart);
  // Status 0 is a process that ended its work or was told to stop.
  EXPECT_EQ(policy.OnExit(60, Exited(0), true).verdict, ExitVerdict::kFinished);
}

TEST(RestartPolicyTest, TheMonitorWaitsLongerThanAnyRestartTakes) {
  for (double cap : {1.0, 10.0, 30.0, 120.0}) {
    RestartLimits limits;
    limits.max_backoff = cap;
    RestartPolicy policy(limits);
    // The longest a process is silent while it is restarted: its backoff and its time to get
    // ready (the launcher stops the run when it is not ready by then).
    double longest_wait = 0;
    for (int k = 0; k < limits.max_restarts; ++k) {
      longest_wait = std::max(longest_wait, policy.OnExit(20, Killed(SIGSEGV), true).delay);
    }
    EXPECT_GT(MonitorSilenceLimit(limits), longest_wait + limits.ready_timeout) << cap;
  }
}

}  // namespace
}  // namespace rl::launch
