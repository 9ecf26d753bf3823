// What a run is, as data: its processes (role, command line, log, readiness, restart policy) and
// its identity (folder, run id, LCM URLs, key). BuildRunPlan() is the one definition of a run's
// processes; a Placement (placement.h) then turns each planned process into what to execute,
// here on this host, on a cluster through Slurm. Nothing here starts or touches anything.
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "launch/launch_options.h"
#include "launch/preset.h"
#include "launch/run_folder.h"

namespace rl::launch {

/// LCM's TCP hub, lcm.lcm.TCPService, from Debian's liblcm-java.
inline constexpr char kLcmJar[] = "/usr/share/java/lcm.jar";

/// How the launcher knows that a process has started and may be relied on.
struct Readiness {
  enum Kind {
    kLogLine,    // a line of its log, written since this start, begins with `text`
    kOpensFile,  // it holds the file `text` open (lcm-logger prints nothing when it starts)
    kListens,    // a TCP socket of this host listens on port `text` (LCM's TCP hub)
    kAtStart,    // at once
  };
  Kind kind = kAtStart;
  std::string text;
};

/// One process of a run.
struct PlannedProcess {
  std::string role;   // its name in logs, RUN/pids and RUN/restarts: "replay", "actor-3", "monitor"
  std::string kind;   // its program: "hub", "recorder", "replay", "learner", "evaluator", "actor",
                      // "monitor"
  int actor_id = -1;  // actors: the index, 0 .. num_actors - 1
  std::vector<std::string> argv;  // argv[0]: the program (a path, or a name looked up on PATH)
  std::string log;                // its standard output and error are appended to this file
  Readiness ready;
  bool restart = true;    // started again (restart_policy.h) when it exits while the run goes on
  bool essential = true;  // down for good, it ends the run (an actor down leaves the others going)
  bool ends_run = false;  // its exit ends the run (the monitor, which decides when it is over)
  bool shown = false;     // its output is also the launcher's (the monitor's progress line)
  bool stops_last = false;  // stopped after every other process (the recorder, to record them
                            // all; then the TCP hubs, which carry what it records)
  // A folder where it writes files atomically (NAME.tmp.<pid>, then renamed) as it stops: the
  // replay its last snapshot, the learner its checkpoint and state. While such a file there
  // grows, its stop is waited for beyond the usual seconds (RestartLimits::stop_stall_seconds).
  std::string writes_at_stop;
};

/// What a run's plan is built from, resolved from the command line, the preset and, when
/// resuming, the run's own header.
struct RunSettings {
  std::string preset;       // its name
  std::string preset_path;  // the file read (configs/NAME.ini, or RUN/config.ini when resuming)
  bool resume = false;
  int actors = 4;      // actor processes started here
  int num_actors = 4;  // actors in the whole run (ids 0 .. num_actors - 1; Ape-X epsilons)
  uint64_t seed = 1;
  std::string goal;  // as given or as the preset has it
  double time_budget = 600;
  int ttl = 0;
  std::string transport = "udpm";  // "udpm": LCM multicast; "tcp": LCM's TCP hub (tcpq://)
  std::string hub_host;            // tcp: the numeric address the hubs listen on
  bool record = false;
  int record_mb = 256;
  std::map<std::string, std::vector<std::string>> extra_args;  // by kind
  RestartLimits limits;
  std::string bin_dir;  // where replay, learner, evaluator, actor and monitor are
};

/// Resolves the settings: the command line wins; then, when resuming, the run's header (actors,
/// num_actors, seed; not its goal); then the preset (top-level "actors", [evaluator] "goal"); then
/// the defaults. Throws LaunchError when the preset's actors is not a whole number, when there is
/// no goal anywhere, or when num_actors < actors.
RunSettings ResolveSettings(const LaunchOptions& options, const Preset& preset,
                            const RunHeader* resumed, const std::string& bin_dir);

/// Where a run lives and how its processes find each other.
struct RunIdentity {
  std::string run_dir;  // absolute
  int64_t run_id = 0;
  int port = 0;  // main LCM port; the bulk port is port + 1, the samples port port + 2
};

/// A run: settings, identity, and its processes in the order they start.
struct RunPlan {
  RunSettings settings;
  RunIdentity identity;
  std::string lcm_url;
  std::string lcm_bulk_url;
  // The samples port's (udpm: port + 2); through TCP hubs the bulk port's, whose hub forwards a
  // channel to its subscribers only.
  std::string lcm_samples_url;
  std::string config_file;  // RUN/config.ini: the header and the preset, every process's --config
  std::string key_file;     // RUN/key
  double monitor_silence = 0;  // the monitor's --stale-seconds (MonitorSilenceLimit)
  std::vector<PlannedProcess> processes;

  /// The header of RUN/config.ini for this run (`started`: its start time).
  RunHeader Header(const std::string& started) const;
};

/// The LCM URL of a run's port on this host's multicast group.
std::string LcmUrl(int port, int ttl);

/// The LCM URL of a run's port through LCM's TCP hub on `host` (a numeric address: liblcm 1.3.1
/// resolves names in tcpq URLs to 0.0.0.0).
std::string TcpHubUrl(const std::string& host, int port);

/// Builds the run's plan: the TCP hubs of the main and bulk ports (transport "tcp"), the
/// recorder (with --record), the replay, the learner, the evaluator, actors 0 .. actors - 1 and
/// the monitor, in that order, each with its command line (the common
/// options, its own, then the user's extra ones), log, readiness line and
/// restart policy.
RunPlan BuildRunPlan(const RunSettings& settings, const RunIdentity& identity);

}  // namespace rl::launch
