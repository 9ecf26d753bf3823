// launcher: runs a whole run on this host (scripts/launch.sh is its entry point; see
// LaunchUsage() in launch_options.cc and README.md). Checks its input before anything starts,
// creates and locks the run folder, builds the run's plan and supervises it.
#include <unistd.h>

#include <cerrno>
#include <csignal>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <memory>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "common/atomic_file.h"
#include "common/clock.h"
#include "common/host_ports.h"
#include "common/text_format.h"
#include "launch/launch_options.h"
#include "launch/placement.h"
#include "launch/preset.h"
#include "launch/proc.h"
#include "launch/run_folder.h"
#include "launch/run_plan.h"
#include "launch/slurm_placement.h"
#include "launch/supervisor.h"
#include "launch/watchdog.h"

namespace {

namespace fs = std::filesystem;
using namespace rl::launch;

void Say(int fd, const std::string& text) { (void)!write(fd, text.data(), text.size()); }

std::string ReadText(const std::string& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

// Opens `path` with `mode` and closes it: empty (trunc), or there as it was (app).
void Touch(const std::string& path, std::ios::openmode mode) { std::ofstream file(path, mode); }

// A run's three free UDP ports (rl::PickRunPorts).
int PickFreePort() {
  const int port = rl::PickRunPorts(100);
  if (port == 0) throw LaunchError("no three free UDP ports found in 100 tries (pass --port)");
  return port;
}

bool OnPath(const std::string& program) {
  const char* path = std::getenv("PATH");
  std::istringstream dirs(path != nullptr ? path : "");
  for (std::string dir; std::getline(dirs, dir, ':');) {
    if (!dir.empty() && access((dir + "/" + program).c_str(), X_OK) == 0) return true;
  }
  return false;
}

// The default run folder of a new run: ROOT/runs/PRESET-YYYYmmdd-HHMMSS.
std::string DefaultRunFolder(const std::string& root, const std::string& preset) {
  return root + "/runs/" + preset + "-" + LocalTimeNow("%Y%m%d-%H%M%S");
}

// "launch.sh --stop RUN_DIR": SIGTERM to the run's launcher, as Ctrl-C would stop it; returns
// once it has ended (its processes stopped), 1 when the run is not going.
int StopRun(const std::string& given) {
  std::error_code ec;
  const std::string dir = fs::absolute(given, ec).lexically_normal().string();
  if (!fs::is_directory(dir, ec)) throw LaunchError("no run folder '" + given + "'");
  if (!fs::is_regular_file(dir + "/config.ini", ec)) {
    throw LaunchError(dir + " has no config.ini: not a run folder");
  }
  const std::optional<pid_t> pid = RunningLauncher(dir);
  if (!pid) {
    Say(STDOUT_FILENO, "launch: the run in " + dir + " is not going\n");
    return 1;
  }
  const uint64_t start = ProcessStartTime(*pid);
  Say(STDOUT_FILENO,
      "launch: stopping the run in " + dir + " (launcher, pid " + std::to_string(*pid) + ")\n");
  kill(*pid, SIGTERM);
  // Its processes get 10 s to stop before they are killed, those still writing their last files
  // up to stop_write_limit, and its recorder a few seconds more.
  const double limit = RestartLimits{}.stop_write_limit + 60;
  const double deadline = rl::MonoSeconds() + limit;
  while (rl::MonoSeconds() < deadline) {
    if (!SameProcessAlive(*pid, start)) {
      Say(STDOUT_FILENO, "launch: stopped\n");
      return 0;
    }
    usleep(100 * 1000);
  }
  throw LaunchError("the run in " + dir + " has not stopped after " +
                    rl::FormatDouble("%.0f", limit) + " s (pid " + std::to_string(*pid) + ")");
}

// The run's folders and files before its processes start: config.ini (the header and the preset;
// a resumed run's gets a line), the key, pids, restarts, launch.pid and fresh logs.
void PrepareRunFolder(const RunPlan& plan, const std::string& preset_text) {
  const std::string& dir = plan.identity.run_dir;
  std::error_code ec;
  for (const char* sub : {"logs", "checkpoints", "report"})
    fs::create_directories(dir + "/" + sub, ec);
  if (plan.settings.record) fs::create_directories(dir + "/lcm-log", ec);
  if (ec) throw LaunchError("cannot create the folders of " + dir + ": " + ec.message());
  const RunSettings& s = plan.settings;
  if (s.resume) {
    std::ofstream(plan.config_file, std::ios::app)
        << "# resumed " << IsoNow() << ": actors = " << s.actors
        << ", time budget = " << rl::FormatDouble("%.15g", s.time_budget) << " s\n";
  } else {
    rl::WriteFileAtomically(plan.config_file,
                            FormatRunHeader(plan.Header(IsoNow())) + "\n" + preset_text,
                            "the run's config");
  }
  EnsureKeyFile(plan.key_file);
  Touch(dir + "/pids", std::ios::trunc);
  Touch(dir + "/restarts", s.resume ? std::ios::app : std::ios::trunc);
  if (!s.resume) {
    for (const PlannedProcess& p : plan.processes) Touch(p.log, std::ios::trunc);
  }
  WriteLaunchPid(dir);
}

// "best evaluation mean 475.2 over 7 evaluations" from RUN/eval.jsonl, rounded down as the report
// shows it; empty without evaluations.
std::string BestEvaluation(const std::string& dir) {
  std::ifstream in(dir + "/eval.jsonl");
  double best = 0;
  int n = 0;
  for (std::string line; std::getline(in, line);) {
    const nlohmann::json row = nlohmann::json::parse(line, nullptr, /*allow_exceptions=*/false);
    if (!row.is_object() || !row.contains("mean") || !row["mean"].is_number()) continue;
    const double mean = row["mean"].get<double>();
    if (n == 0 || mean > best) best = mean;
    ++n;
  }
  if (n == 0) return "";
  return rl::Score(best) + " over " + std::to_string(n) + " evaluation" + (n == 1 ? "" : "s");
}

void SaySummary(const RunPlan& plan, RunEnd end) {
  const std::string& dir = plan.identity.run_dir;
  std::string text =
      "launch: run folder " + dir + "\nlaunch: report " + dir + "/report/index.html\n";
  if (plan.settings.record) {
    int64_t bytes = 0;
    std::error_code ec;
    for (const auto& entry : fs::directory_iterator(dir + "/lcm-log", ec)) {
      std::error_code size_ec;
      bytes += static_cast<int64_t>(entry.file_size(size_ec));
    }
    text += "launch: LCM recording " + dir + "/lcm-log/ (" +
            rl::FormatDouble("%.1f", static_cast<double>(bytes) / 1e6) + " MB)\n";
  }
  if (const std::string best = BestEvaluation(dir); !best.empty()) {
    text += "launch: best evaluation mean " + best + "\n";
  }
  text += "launch: goal of " + plan.settings.goal +
          (end == RunEnd::kGoalReached ? " reached\n" : " not reached\n");
  Say(STDOUT_FILENO, text);
}

// Everything a launch checks before it creates or touches a run folder.
struct CheckedInput {
  std::optional<RunHeader> resumed;
  std::string run_dir;  // resuming: the run's folder
  std::string preset_text;
  RunSettings settings;
};

CheckedInput CheckInput(const LaunchOptions& o, const std::string& root, const std::string& bin) {
  CheckedInput in;
  std::error_code ec;
  std::string preset_path;
  if (o.mode == Mode::kResume) {
    in.run_dir = fs::absolute(o.run_dir, ec).lexically_normal().string();
    if (!fs::is_directory(in.run_dir, ec)) throw LaunchError("no run folder '" + o.run_dir + "'");
    preset_path = in.run_dir + "/config.ini";
    if (!fs::is_regular_file(preset_path, ec)) {
      throw LaunchError(in.run_dir + " has no config.ini: not a run folder");
    }
    in.resumed = ParseRunHeader(ReadText(preset_path), preset_path);
  } else {
    preset_path = root + "/configs/" + o.preset + ".ini";
    if (o.preset.find('/') != std::string::npos || !fs::is_regular_file(preset_path, ec)) {
      std::set<std::string> known;
      for (const auto& entry : fs::directory_iterator(root + "/configs", ec)) {
        if (entry.path().extension() == ".ini") known.insert(entry.path().stem().string());
      }
      std::string list;
      for (const std::string& k : known) list += (list.empty() ? "" : " ") + k;
      throw LaunchError("no preset '" + o.preset + "' (known: " + list + ")");
    }
  }
  const Preset preset = Preset::Read(preset_path);
  in.preset_text = ReadText(preset_path);
  for (const char* program : {"replay", "learner", "evaluator", "actor", "monitor"}) {
    if (access((bin + "/" + program).c_str(), X_OK) != 0) {
      throw LaunchError(bin + "/" + program + " is missing (build first, or drop --no-setup)");
    }
  }
  CheckPreset(preset, ListOptionNames(bin, {"actor", "replay", "learner", "evaluator"}));
  in.settings = ResolveSettings(o, preset, in.resumed ? &*in.resumed : nullptr, bin);
  if (in.resumed && o.or_resume) {
    if ((o.seed && *o.seed != in.resumed->seed) || (o.run_id && *o.run_id != in.resumed->run_id)) {
      throw LaunchError("--seed and --run-id cannot change the run in " + in.run_dir +
                        " (resumed: it holds a run already)");
    }
  }
  if (o.record && !OnPath("lcm-logger")) {
    throw LaunchError("--record needs lcm-logger (Debian's liblcm-bin: scripts/setup.sh)");
  }
  return in;
}

// --dry-run: the plan, as it would run (a new run's folder, id and port as they would be chosen).
int SayPlan(const LaunchOptions& o, const CheckedInput& in, const std::string& root,
            const Placement& placement) {
  RunIdentity id;
  if (in.resumed) {
    id = {in.run_dir, in.resumed->run_id, o.port.value_or(in.resumed->Port())};
  } else {
    id.run_dir = o.out.empty() ? DefaultRunFolder(root, o.preset) : o.out;
    id.run_id = o.run_id.value_or(0);
    id.port = o.port.value_or(0);
  }
  const RunPlan plan = BuildRunPlan(in.settings, id);
  std::string text =
      "launch: dry run of '" + plan.settings.preset + "' on " + placement.Describe() + " (" +
      (in.resumed ? "resumed" : "run id, port and folder not chosen yet") + "): nothing started\n";
  for (const PlannedProcess& p : plan.processes) {
    text += p.role + ":";
    for (const std::string& word : placement.Command(p)) text += " " + word;
    text += "\n";
  }
  Say(STDOUT_FILENO, text);
  return 0;
}

// --slurm: the job's nodes and the actors of each, checked before anything starts.
std::unique_ptr<SlurmPlacement> PlaceInSlurmJob(LaunchOptions* o) {
  if (o->transport == "tcp" && access(kLcmJar, R_OK) != 0) {
    throw LaunchError(std::string("--transport tcp needs LCM's TCP hub in ") + kLcmJar +
                      " (Debian's liblcm-java)");
  }
  if (o->transport == "tcp" && !OnPath("java")) {
    throw LaunchError("--transport tcp needs java on the PATH for LCM's TCP hub");
  }
  SlurmJob job = ReadSlurmJob();
  std::vector<int> actors = ActorsPerNode(job.cpus, o->actors_per_node);
  return std::make_unique<SlurmPlacement>(std::move(job), std::move(actors));
}

int Launch(LaunchOptions o) {
  std::error_code ec;
  const std::string root =
      fs::absolute(o.root.empty() ? RL_SOURCE_DIR : o.root, ec).lexically_normal().string();
  const std::string bin = ExecutableDir();
  // --or-resume, and a run in --out already (a requeued job): a resume of it.
  if (o.or_resume && fs::is_regular_file(o.out + "/config.ini", ec)) {
    o.mode = Mode::kResume;
    o.run_dir = o.out;
  }
  std::unique_ptr<SlurmPlacement> slurm;
  if (o.slurm) slurm = PlaceInSlurmJob(&o);
  CheckedInput in = CheckInput(o, root, bin);
  if (slurm) {
    // Every node's actors; the run's actor count may grow (a bigger job), never shrink.
    in.settings.actors = slurm->TotalActors();
    const int wanted = o.num_actors.value_or(0);
    if (wanted != 0 && wanted < in.settings.actors) {
      throw LaunchError("--num-actors (" + std::to_string(wanted) + ") must be at least the " +
                        std::to_string(in.settings.actors) + " actors of the job's nodes");
    }
    in.settings.num_actors = std::max(
        {in.settings.actors, wanted, in.resumed ? in.resumed->num_actors : in.settings.actors});
    in.settings.ttl = 1;
    in.settings.hub_host = slurm->job().first_address;
  }
  const LocalPlacement local;
  const Placement& placement = slurm ? static_cast<const Placement&>(*slurm) : local;
  if (o.dry_run) return SayPlan(o, in, root, placement);

  // The folder, created (or, resuming, found) and locked for the launcher's life.
  std::unique_ptr<RunLock> lock;
  RunIdentity id;
  if (in.resumed) {
    id.run_dir = in.run_dir;
    lock = std::make_unique<RunLock>(id.run_dir);
    id.run_id = in.resumed->run_id;
    // The resumed run keeps its port, so that its config.ini and scripts/spy.sh stay right.
    id.port = o.port.value_or(in.resumed->Port());
    if (!o.port && !slurm && (id.port == 0 || rl::RunPortsInUse(id.port))) {
      throw LaunchError("the run's LCM port " + std::to_string(id.port) +
                        " is in use: is the run still going? (or pass --port)");
    }
  } else {
    id.port = o.port ? *o.port : PickFreePort();
    id.run_id = o.run_id ? *o.run_id : RandomRunId();
    const std::string out = o.out.empty() ? DefaultRunFolder(root, o.preset) : o.out;
    id.run_dir = CreateRunFolder(out, o.out.empty());
    lock = std::make_unique<RunLock>(id.run_dir);
  }
  const RunPlan plan = BuildRunPlan(in.settings, id);
  PrepareRunFolder(plan, in.preset_text);

  Say(STDOUT_FILENO,
      "launch: run " + std::to_string(id.run_id) + " of '" + plan.settings.preset + "' in " +
          id.run_dir + " (LCM port " + std::to_string(id.port) + ", " +
          (plan.settings.transport == "tcp" ? "TCP hub " + plan.settings.hub_host
                                            : "ttl " + std::to_string(plan.settings.ttl)) +
          ") on " + placement.Describe() + (plan.settings.resume ? ", resumed" : "") + "\n");
  const int signal_fd = BlockRunSignals();
  Watchdog watchdog(plan.settings.limits);
  Supervisor supervisor(plan, placement, signal_fd, &watchdog);
  supervisor.OnAllReady([&plan] {
    const std::string& dir = plan.identity.run_dir;
    std::string text = "launch: " + std::to_string(plan.settings.actors) +
                       " actors, replay, learner and evaluator running; logs in " + dir +
                       "/logs\nlaunch: watch it with scripts/spy.sh --run " + dir + "\n";
    if (plan.settings.record) {
      text += "launch: recording the main port into " + dir +
              "/lcm-log/ (replay: see README, Recording a run)\n";
    }
    Say(STDOUT_FILENO, text);
  });
  const RunEnd end = supervisor.Run();
  if (end == RunEnd::kGoalReached || end == RunEnd::kNotReached || end == RunEnd::kProcessDown) {
    SaySummary(plan, end);
  }
  return ExitStatusOf(end);
}

}  // namespace

int main(int argc, char** argv) {
  signal(SIGPIPE, SIG_IGN);  // a closed terminal or pipe must not end the launcher mid-stop
  try {
    const LaunchOptions options = ParseLaunchArgs(std::vector<std::string>(argv + 1, argv + argc));
    switch (options.mode) {
      case Mode::kHelp:
        Say(STDOUT_FILENO, LaunchUsage());
        return 0;
      case Mode::kStop:
        return StopRun(options.run_dir);
      default:
        return Launch(options);
    }
  } catch (const LaunchError& e) {
    Say(STDERR_FILENO, std::string("launch: ") + e.what() + "\n");
    return 2;
  } catch (const std::exception& e) {
    Say(STDERR_FILENO, std::string("launch: error: ") + e.what() + "\n");
    return 2;
  }
}
