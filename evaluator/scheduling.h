// The evaluator's CPU scheduling: a lower priority than the learner's, so that scoring, the second
// metric, the videos and the t-SNE maps run on the cycles the learner, the replay and the actors
// leave, and never slow the learner down. What is scored and how is unchanged: only when.
//
// Linux applies a scheduling policy and a nice value to one thread, and a thread inherits both
// from the thread that starts it. So ApplyScheduling() is called first thing in main(), before any
// thread starts, and the whole process then runs at that priority.
#pragma once

#include <string>

namespace rl::evaluator {

/// The Linux scheduling policies a process may lower itself to (sched(7)).
enum class SchedPolicy {
  kNormal,  // SCHED_OTHER: the default time-sharing policy, weighted by the nice value
  kBatch,   // SCHED_BATCH: as SCHED_OTHER, but a waking thread does not preempt a running one
  kIdle,    // SCHED_IDLE: runs only when no SCHED_OTHER or SCHED_BATCH thread wants the core
            // (a weight below nice 19's); the nice value does not matter under it
};

/// A policy and a nice value (0 .. 19: the evaluator may only lower its priority).
struct Scheduling {
  SchedPolicy policy = SchedPolicy::kNormal;
  int nice = 0;
};

/// "normal", "batch" or "idle".
const char* SchedPolicyName(SchedPolicy policy);

/// The policy named "normal", "batch" or "idle". Throws std::invalid_argument naming the bad
/// value and the accepted ones.
SchedPolicy ParseSchedPolicy(const std::string& name);

/// `nice` when it is 0 .. 19; throws std::invalid_argument otherwise.
int CheckNice(int nice);

/// Scheduling from the option values (ParseSchedPolicy, CheckNice).
Scheduling ParseScheduling(const std::string& policy, int nice);

/// Sets the calling thread's policy (priority 0) and nice value; threads it starts afterwards
/// inherit both. Throws std::runtime_error with the system's reason when the kernel refuses.
void ApplyScheduling(const Scheduling& scheduling);

/// The calling thread's policy and nice value, as the kernel has them. Throws std::runtime_error
/// for a policy other than the three above (a real-time one, set by someone else).
Scheduling CurrentScheduling();

/// "idle, nice 19".
std::string Describe(const Scheduling& scheduling);

/// Describe(CurrentScheduling()), or what the kernel said when that throws: what the evaluator
/// prints when it starts. Never throws.
std::string DescribeCurrent();

}  // namespace rl::evaluator
