// A run placed by Slurm: the launcher runs in a job's batch script on the job's first node and
// starts each process as a job step with srun (`srun --nodes=1 --ntasks=1 --nodelist=NODE
// --overlap ...`): the replay, learner and evaluator on the first node, actors on every node. The
// monitor, the recorder and LCM's TCP hubs run beside the launcher, in the batch step (the hubs
// are JVMs, which keep SIGUSR2 for themselves). The supervisor starts, watches, restarts and stops
// each srun like any local process; the step's output reaches the process's log through srun.
//
// Facts of Slurm 22.05 this rests on (tests/cluster/README.md): srun passes USR1 and USR2 on to
// its task, while TERM or HUP to srun SIGKILLs the task, so a step is stopped with USR2 (which
// our processes take as a clean stop); srun returns its task's status (128 + the signal for a
// killed one); when a node is lost, its steps' sruns return 0 ("Node failure") once Slurm declares
// it down, a job submitted with --no-kill goes on without it, and a new srun to it fails.
#pragma once

#include <optional>
#include <set>
#include <string>
#include <vector>

#include "launch/placement.h"

namespace rl::launch {

/// The job the launcher runs in, from Slurm's environment and scontrol.
struct SlurmJob {
  std::string job_id;
  std::vector<std::string> nodes;  // nodes[0]: the launcher's own (the first node), then the rest
  std::vector<int> cpus;           // the job's cores on each node, as nodes
  std::string first_address;       // nodes[0]'s NodeAddr (a numeric address)
};

/// Reads SLURM_JOB_CPUS_PER_NODE ("8(x2),4": 8 on two nodes, then 4) for `nodes` nodes. Throws
/// LaunchError when it is malformed or names another number of nodes.
std::vector<int> ParseCpusPerNode(const std::string& text, size_t nodes);

/// The processes the first node runs besides its actors: the replay, the learner, the evaluator.
inline constexpr int kFirstNodeProcesses = 3;

/// Actors on each node: `per_node` on every one when given, else the node's cores (the first
/// node's less kFirstNodeProcesses). Throws LaunchError, with what to ask Slurm for, when the
/// first node has fewer cores than its processes need, when a node has fewer cores than
/// `per_node` actors need, or when no actor is left.
std::vector<int> ActorsPerNode(const std::vector<int>& cpus, std::optional<int> per_node);

/// The job this process runs in. Throws LaunchError when srun or scontrol is not on the PATH,
/// when it is not inside a Slurm job, or when Slurm's answers cannot be read.
SlurmJob ReadSlurmJob();

class SlurmPlacement final : public Placement {
 public:
  /// `actors[i]` actors on job.nodes[i] (ActorsPerNode), ids in node order.
  SlurmPlacement(SlurmJob job, std::vector<int> actors);

  std::string Describe() const override;
  /// srun ... ARGV for the replay, learner, evaluator and actors; the argv itself for the rest.
  std::vector<std::string> Command(const PlannedProcess& process) const override;
  /// SIGUSR2 for a step, SIGTERM for the rest.
  int StopSignal(const PlannedProcess& process) const override;
  /// For an actor of another node: "its node node2 has left the job (down*)" once Slurm no longer
  /// counts the node in the job or has it down, not responding, drained or failed.
  std::string Lost(const PlannedProcess& process) const override;
  /// "the Slurm job 12 is completing" once the job is no longer RUNNING (squeue).
  std::string Ending() const override;

  /// The node of actor `id`.
  const std::string& NodeOf(int actor_id) const;
  int TotalActors() const { return total_; }
  const SlurmJob& job() const { return job_; }

 private:
  static bool IsStep(const PlannedProcess& p);
  SlurmJob job_;
  std::vector<int> actors_;
  int total_ = 0;
  mutable std::set<std::string> lost_;  // nodes known to be lost
};

}  // namespace rl::launch
