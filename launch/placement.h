// Where a planned process runs: the small step between a run's plan (run_plan.h) and the
// supervisor (supervisor.h), which executes Command(process) for each process and watches what it
// starts. On this host the command is the process's own argv; a placement on a cluster returns a
// command that runs the same argv on a node of its choosing (for Slurm: srun --nodes=1
// --ntasks=1 --nodelist=NODE --overlap ... ARGV, whose client process the supervisor then starts,
// restarts and stops like any other).
#pragma once

#include <csignal>
#include <string>
#include <vector>

#include "launch/run_plan.h"

namespace rl::launch {

class Placement {
 public:
  virtual ~Placement() = default;

  /// Where the run's processes go, for the launcher's first line ("this host").
  virtual std::string Describe() const = 0;

  /// The command the supervisor executes for `process` (argv[0] looked up on PATH when it has no
  /// '/'). Called for every start, restarts included; must not fail.
  virtual std::vector<std::string> Command(const PlannedProcess& process) const = 0;

  /// The signal that asks the command started for `process` to stop cleanly (also its
  /// parent-death signal): SIGTERM here; SIGUSR2 for an srun, which passes USR2 on to its task
  /// where TERM would make it SIGKILL the task.
  virtual int StopSignal(const PlannedProcess& /*process*/) const { return SIGTERM; }

  /// Called when `process` has exited while the run goes on: why it cannot run any more (its
  /// node has left the job), or empty. May take a moment (a query to the cluster); not called
  /// otherwise.
  virtual std::string Lost(const PlannedProcess& /*process*/) const { return ""; }

  /// Called when a process has exited while the run goes on: why the whole run is being ended
  /// from outside (its Slurm job cancelled or requeued: Slurm has stopped its processes), or
  /// empty. May take a moment.
  virtual std::string Ending() const { return ""; }
};

/// Every process on this host, as planned.
class LocalPlacement final : public Placement {
 public:
  std::string Describe() const override { return "this host"; }
  std::vector<std::string> Command(const PlannedProcess& process) const override {
    return process.argv;
  }
};

}  // namespace rl::launch
