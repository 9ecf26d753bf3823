// The launcher's command line (scripts/launch.sh passes on everything but --no-setup and
// --build-dir): parsed and checked before anything starts, so that bad input gets one clear line
// and leaves nothing behind.
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

namespace rl::launch {

/// An error in what the user asked for (options, preset, run folder): the launcher prints
/// "launch: <what>" and exits with status 2.
class LaunchError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// When a process that exited is started again (restart_policy.h), and how long it may take to
/// get ready. Seconds throughout.
struct RestartLimits {
  int max_restarts = 5;        // restarts in a row of one process; then it is down for good
  double first_backoff = 1;    // wait before the first restart; doubled for each further one
  double max_backoff = 10;     // the wait's cap
  double reset_after = 300;    // a process that ran this long before it exited starts a new count
  double startup_seconds = 3;  // an error exit this soon after a start is a startup failure
  double ready_timeout = 30;   // a process not ready this long after its start is a failure
  // Stopping: a process still running this long after SIGTERM is killed, unless it is writing
  // (PlannedProcess::writes_at_stop): then once its temporary file has not grown for
  // stop_stall_seconds, or stop_write_limit after the SIGTERM.
  double stop_seconds = 10;
  double stop_stall_seconds = 20;
  double stop_write_limit = 600;
};

enum class Mode { kRun, kResume, kStop, kHelp };

/// The command line. Optional fields left empty take the preset's value (or, when resuming, the
/// run's own) in ResolveSettings (run_plan.h).
struct LaunchOptions {
  Mode mode = Mode::kRun;
  std::string preset;   // kRun: a preset of ROOT/configs, by name
  std::string run_dir;  // kResume, kStop: the run folder as given
  std::string root;     // the checkout: presets in ROOT/configs, default run folders in ROOT/runs
  std::string out;      // kRun: the run folder; empty: ROOT/runs/PRESET-YYYYmmdd-HHMMSS
  std::optional<int> actors;
  std::optional<int> num_actors;
  double time_budget = 600;
  std::optional<std::string> goal;  // as given: the text is passed on to the processes
  std::optional<uint64_t> seed;
  int ttl = 0;
  std::string transport = "udpm";  // "udpm" or "tcp"
  std::optional<int> port;
  std::optional<int64_t> run_id;
  // Extra options of every process of a kind ("actor", "replay", "learner", "evaluator"), split
  // at white space.
  std::map<std::string, std::vector<std::string>> extra_args;
  bool record = false;
  int record_mb = 256;
  RestartLimits limits;
  bool dry_run = false;  // check the input and print the plan; start and create nothing
  // --slurm: inside a Slurm job, every node of it (slurm_placement.h); actors on each node.
  bool slurm = false;
  std::optional<int> actors_per_node;
  // --or-resume (with --out): a folder that holds a run already is resumed (a requeued job).
  bool or_resume = false;
};

/// Parses the arguments after the program name. Throws LaunchError naming the option for an
/// unknown option, a missing value, a value that is not a number of the option's kind or out of
/// its range (--time-budget -5, --actors x), and options that cannot change a resumed run.
LaunchOptions ParseLaunchArgs(const std::vector<std::string>& args);

/// The --help text.
std::string LaunchUsage();

}  // namespace rl::launch
