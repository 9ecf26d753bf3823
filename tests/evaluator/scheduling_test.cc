#include "evaluator/scheduling.h"

#include <sys/wait.h>
#include <unistd.h>

#include <functional>
#include <stdexcept>
#include <thread>

#include <gtest/gtest.h>

namespace rl::evaluator {
namespace {

TEST(ParseScheduling, AcceptsTheThreePoliciesAndNiceZeroToNineteen) {
  EXPECT_EQ(ParseScheduling("normal", 0).policy, SchedPolicy::kNormal);
  EXPECT_EQ(ParseScheduling("batch", 5).policy, SchedPolicy::kBatch);
  const Scheduling idle = ParseScheduling("idle", 19);
  EXPECT_EQ(idle.policy, SchedPolicy::kIdle);
  EXPECT_EQ(idle.nice, 19);
  EXPECT_EQ(Describe(idle), "idle, nice 19");
}

TEST(ParseScheduling, RefusesOtherPoliciesAndNiceOutsideTheRange) {
  EXPECT_THROW(ParseScheduling("fifo", 0), std::invalid_argument);
  EXPECT_THROW(ParseScheduling("", 0), std::invalid_argument);
  EXPECT_THROW(ParseScheduling("idle", -1), std::invalid_argument);  // would raise the priority
  EXPECT_THROW(ParseScheduling("normal", 20), std::invalid_argument);
}

// Runs `body` in a child process (a lowered priority must not stay with the test process) and
// returns its exit status: 0 when every check held.
int InChild(const std::function<int()>& body) {
  const pid_t pid = fork();
  if (pid == 0) _exit(body());
  int status = 0;
  EXPECT_EQ(waitpid(pid, &status, 0), pid);
  return WIFEXITED(status) ? WEXITSTATUS(status) : 100;
}

// Applies `wanted`, then checks the calling thread and a thread started afterwards: exit status
// 1 when the caller differs, 2 when the new thread does, 3 when ApplyScheduling threw.
int AppliedToCallerAndNewThreads(Scheduling wanted) {
  try {
    ApplyScheduling(wanted);
  } catch (const std::exception&) {
    return 3;
  }
  auto same = [&](const Scheduling& s) {
    return s.policy == wanted.policy && s.nice == wanted.nice;
  };
  if (!same(CurrentScheduling())) return 1;
  bool thread_same = false;
  std::thread t([&] { thread_same = same(CurrentScheduling()); });
  t.join();
  return thread_same ? 0 : 2;
}

TEST(ApplyScheduling, IdleReachesTheCallerAndTheThreadsItStartsLater) {
  EXPECT_EQ(InChild([] { return AppliedToCallerAndNewThreads({SchedPolicy::kIdle, 19}); }), 0);
}

TEST(ApplyScheduling, BatchWithANiceValueReachesTheCallerAndLaterThreads) {
  EXPECT_EQ(InChild([] { return AppliedToCallerAndNewThreads({SchedPolicy::kBatch, 7}); }), 0);
}

TEST(ApplyScheduling, NormalAtTheInheritedNiceValueChangesNothing) {
  // The nice value the tests run at (raising the priority back to 0 would need privileges).
  const int inherited = CurrentScheduling().nice;
  EXPECT_EQ(InChild([inherited] {
              return AppliedToCallerAndNewThreads({SchedPolicy::kNormal, inherited});
            }),
            0);
}

}  // namespace
}  // namespace rl::evaluator
