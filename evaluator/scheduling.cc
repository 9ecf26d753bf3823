#include "evaluator/scheduling.h"

#include <sched.h>
#include <sys/resource.h>

#include <cerrno>
#include <cstring>
#include <stdexcept>

namespace rl::evaluator {
namespace {

constexpr int kMaxNice = 19;

int LinuxPolicy(SchedPolicy policy) {
  switch (policy) {
    case SchedPolicy::kBatch:
      return SCHED_BATCH;
    case SchedPolicy::kIdle:
      return SCHED_IDLE;
    case SchedPolicy::kNormal:
      break;
  }
  return SCHED_OTHER;
}

}  // namespace

const char* SchedPolicyName(SchedPolicy policy) {
  switch (policy) {
    case SchedPolicy::kBatch:
      return "batch";
    case SchedPolicy::kIdle:
      return "idle";
    case SchedPolicy::kNormal:
      break;
  }
  return "normal";
}

SchedPolicy ParseSchedPolicy(const std::string& name) {
  if (name == "normal") return SchedPolicy::kNormal;
  if (name == "batch") return SchedPolicy::kBatch;
  if (name == "idle") return SchedPolicy::kIdle;
  throw std::invalid_argument("--sched-policy '" + name + "' is none of normal, batch, idle");
}

int CheckNice(int nice) {
  if (nice < 0 || nice > kMaxNice) {
    throw std::invalid_argument("--nice " + std::to_string(nice) +
                                " is outside 0 .. 19 (the evaluator only lowers its priority)");
  }
  return nice;
}

Scheduling ParseScheduling(const std::string& policy, int nice) {
  return {ParseSchedPolicy(policy), CheckNice(nice)};
}

void ApplyScheduling(const Scheduling& scheduling) {
  const sched_param param{};  // sched_priority 0, the only one of these policies
  if (sched_setscheduler(0, LinuxPolicy(scheduling.policy), &param) != 0) {
    throw std::runtime_error(std::string("cannot set the scheduling policy ") +
                             SchedPolicyName(scheduling.policy) + ": " + std::strerror(errno));
  }
  // PRIO_PROCESS with who 0 is the calling thread on Linux (setpriority(2), BUGS).
  if (setpriority(PRIO_PROCESS, 0, scheduling.nice) != 0) {
    throw std::runtime_error("cannot set nice " + std::to_string(scheduling.nice) + ": " +
                             std::strerror(errno));
  }
}

Scheduling CurrentScheduling() {
  Scheduling s;
  const int policy = sched_getscheduler(0);
  // SCHED_RESET_ON_FORK may be or'ed into the policy.
  switch (policy & ~SCHED_RESET_ON_FORK) {
    case SCHED_OTHER:
      s.policy = SchedPolicy::kNormal;
      break;
    case SCHED_BATCH:
      s.policy = SchedPolicy::kBatch;
      break;
    case SCHED_IDLE:
      s.policy = SchedPolicy::kIdle;
      break;
    default:
      throw std::runtime_error("scheduling policy " + std::to_string(policy) +
                               " is none of normal, batch, idle");
  }
  errno = 0;
  const int nice = getpriority(PRIO_PROCESS, 0);  // -1 is also a valid nice value
  if (nice == -1 && errno != 0) {
    throw std::runtime_error(std::string("cannot read the nice value: ") + std::strerror(errno));
  }
  s.nice = nice;
  return s;
}

std::string Describe(const Scheduling& scheduling) {
  return std::string(SchedPolicyName(scheduling.policy)) + ", nice " +
         std::to_string(scheduling.nice);
}

std::string DescribeCurrent() {
  try {
    return Describe(CurrentScheduling());
  } catch (const std::exception& e) {
    return e.what();
  }
}

}  // namespace rl::evaluator
