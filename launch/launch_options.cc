#include "launch/launch_options.h"

#include <charconv>
#include <cmath>
#include <cstdlib>
#include <sstream>

namespace rl::launch {
namespace {

// A whole number in [min, max], the whole text.
template <typename T>
T ParseWhole(const std::string& option, const std::string& text, T min, T max, const char* what) {
  T v{};
  const char* end = text.data() + text.size();
  const auto [ptr, ec] = std::from_chars(text.data(), end, v);
  if (text.empty() || ec != std::errc() || ptr != end || v < min || v > max) {
    throw LaunchError(option + " must be " + what + ", not '" + text + "'");
  }
  return v;
}

// A finite number, the whole text.
double ParseReal(const std::string& option, const std::string& text, const char* what) {
  char* end = nullptr;
  const double v = text.empty() ? NAN : std::strtod(text.c_str(), &end);
  if (!std::isfinite(v) || end != text.c_str() + text.size()) {
    throw LaunchError(option + " must be " + what + ", not '" + text + "'");
  }
  return v;
}

double ParseSeconds(const std::string& option, const std::string& text) {
  const double v = ParseReal(option, text, "a positive number of seconds");
  if (v <= 0)
    throw LaunchError(option + " must be a positive number of seconds, not '" + text + "'");
  return v;
}

std::vector<std::string> SplitWords(const std::string& text) {
  std::istringstream in(text);
  std::vector<std::string> words;
  for (std::string w; in >> w;) words.push_back(w);
  return words;
}

// The options after PRESET or --resume RUN_DIR.
void ParseRunOptions(const std::vector<std::string>& args, size_t i, LaunchOptions* o) {
  const bool resume = o->mode == Mode::kResume;
  constexpr int kIntMax = 1 << 30;
  for (; i < args.size(); ++i) {
    const std::string& name = args[i];
    if (name == "-h" || name == "--help") {
      o->mode = Mode::kHelp;
      return;
    }
    if (name == "--record" || name == "--dry-run" || name == "--slurm" || name == "--or-resume") {
      (name == "--record"    ? o->record
       : name == "--dry-run" ? o->dry_run
       : name == "--slurm"   ? o->slurm
                             : o->or_resume) = true;
      continue;
    }
    if (name.rfind("--", 0) != 0)
      throw LaunchError("unexpected argument '" + name + "' (see --help)");
    if (i + 1 >= args.size()) throw LaunchError(name + " needs a value (see --help)");
    const std::string& value = args[++i];
    auto refuse_on_resume = [&](const char* what) {
      if (resume) throw LaunchError(name + " cannot change a resumed run's " + what);
    };
    if (name == "--out") {
      refuse_on_resume("folder");
      if (value.empty()) throw LaunchError("--out needs a folder");
      o->out = value;
    } else if (name == "--actors") {
      o->actors = ParseWhole(name, value, 0, 4096, "a whole number from 0 to 4096");
    } else if (name == "--num-actors") {
      o->num_actors = ParseWhole(name, value, 1, 4096, "a whole number from 1 to 4096");
    } else if (name == "--time-budget") {
      o->time_budget = ParseSeconds(name, value);
    } else if (name == "--goal") {
      ParseReal(name, value, "a number (an evaluation mean)");
      o->goal = value;
    } else if (name == "--seed") {
      refuse_on_resume("seed");
      o->seed = ParseWhole<uint64_t>(name, value, 0, UINT64_MAX, "a whole number");
    } else if (name == "--ttl") {
      o->ttl = ParseWhole(name, value, 0, 1, "0 or 1");
    } else if (name == "--transport") {
      if (value != "udpm" && value != "tcp") {
        throw LaunchError("--transport must be udpm (LCM multicast) or tcp (LCM's TCP hub), not '" +
                          value + "'");
      }
      o->transport = value;
    } else if (name == "--actors-per-node") {
      o->actors_per_node = ParseWhole(name, value, 0, 4096, "a whole number from 0 to 4096");
    } else if (name == "--port") {
      o->port =
          ParseWhole(name, value, 1024, 65533, "a UDP port from 1024 to 65533 (P, P+1 and P+2)");
    } else if (name == "--run-id") {
      refuse_on_resume("id");
      o->run_id = ParseWhole<int64_t>(name, value, 1, INT64_MAX, "a positive whole number");
    } else if (name == "--max-restarts") {
      o->limits.max_restarts = ParseWhole(name, value, 0, kIntMax, "a whole number");
    } else if (name == "--max-backoff") {
      o->limits.max_backoff = ParseSeconds(name, value);
    } else if (name == "--reset-restarts-after") {
      o->limits.reset_after = ParseSeconds(name, value);
    } else if (name == "--record-mb") {
      o->record_mb = ParseWhole(name, value, 8, kIntMax, "a whole number of at least 8");
    } else if (name == "--root") {
      o->root = value;
    } else if (name == "--actor-args" || name == "--replay-args" || name == "--learner-args" ||
               name == "--evaluator-args") {
      o->extra_args[name.substr(2, name.size() - 7)] = SplitWords(value);
    } else {
      throw LaunchError("unknown option '" + name + "' (see --help)");
    }
  }
  if (o->transport == "tcp" && !o->slurm) {
    throw LaunchError("--transport tcp needs --slurm (on one host, multicast is the transport)");
  }
  if (o->actors_per_node && !o->slurm) throw LaunchError("--actors-per-node needs --slurm");
  if (o->slurm && o->actors) {
    throw LaunchError("--slurm places actors on every node: use --actors-per-node, not --actors");
  }
  if (o->or_resume && (resume || o->out.empty())) {
    throw LaunchError("--or-resume goes with PRESET --out DIR");
  }
  if (o->actors && o->num_actors && *o->num_actors < *o->actors) {
    throw LaunchError("--num-actors (" + std::to_string(*o->num_actors) +
                      ") must be at least --actors (" + std::to_string(*o->actors) + ")");
  }
}

}  // namespace

LaunchOptions ParseLaunchArgs(const std::vector<std::string>& args) {
  LaunchOptions o;
  size_t at = 0;
  // --root DIR may come first (scripts/launch.sh puts it there), before the mode.
  while (at + 1 < args.size() && args[at] == "--root") {
    o.root = args[at + 1];
    at += 2;
  }
  if (at >= args.size()) throw LaunchError("no preset given (see --help)");
  const std::string& first = args[at];
  if (first == "-h" || first == "--help") {
    o.mode = Mode::kHelp;
    return o;
  }
  size_t i = at + 1;
  if (first == "--stop") {
    if (args.size() != at + 2) throw LaunchError("--stop takes a run folder and nothing else");
    o.mode = Mode::kStop;
    o.run_dir = args[at + 1];
    return o;
  }
  if (first == "--resume") {
    if (args.size() < at + 2) throw LaunchError("--resume needs a run folder");
    o.mode = Mode::kResume;
    o.run_dir = args[at + 1];
    i = at + 2;
  } else if (first.rfind('-', 0) == 0) {
    throw LaunchError(
        "the first argument must be a preset, --resume RUN_DIR or --stop RUN_DIR, not '" + first +
        "' (see --help)");
  } else {
    o.preset = first;
  }
  ParseRunOptions(args, i, &o);
  return o;
}

std::string LaunchUsage() {
  return R"(Usage: scripts/launch.sh PRESET [options]
       scripts/launch.sh --resume RUN_DIR [options]
       scripts/launch.sh --stop RUN_DIR

Starts a whole run: the replay daemon, the learner, the evaluator and N actors, talking over LCM,
with a live progress line. Stops every process when an evaluation reaches the goal (exit 0) or
the time budget runs out (exit 1); Ctrl-C, SIGTERM and --stop stop the run cleanly (exit 130), and
so does a hang-up, its terminal closed (exit 129). Bad input is refused before anything starts
(exit 2), and so is a preset key or section that no process knows.

The launcher supervises every process: one that fails while the run goes on (a crash, an error
status, a signal it does not handle, such as SIGKILL) is started again after 1, 2, 4, ... s (at
most --max-backoff), at most --max-restarts times in a row; one that ran --reset-restarts-after
seconds before it exited starts a new count. One that fails with an error status before it is
ready, or within 3 s of its start, is not restarted: the run stops at once with its log (a
snapshot or state it refuses, a bad option). The learner always starts with --resume and the
replay with --snapshot RUN/replay-snapshot.bin, so that a restarted one continues. Restarts are
lines of RUN/restarts, of the process's log and of the progress line. One that exits with status 0
(its work done, or a SIGTERM, which every process takes as a clean stop) is left down: the run
goes on without an actor or the recorder; any other process down ends it (exit 1).
Should the launcher itself die (killed, a crash), its processes get SIGTERM, so that they write
their last snapshot and state, and a watchdog kills those still running 10 s later. A stop
(Ctrl-C, --stop, the end of the run) gives every process 10 s, and waits longer for the replay's
last snapshot and the learner's state while their files grow (at most 10 min).

  PRESET                 a preset in configs/ (cartpole, ...)
  --resume RUN_DIR       continue a stopped or crashed run in its folder: its copy of the
                         preset, run id and seed; the learner from its saved state, the
                         replay from its snapshot, the evaluator's history and the metrics
                         kept (options as below, except --out, --seed and --run-id)
  --stop RUN_DIR         stop the run going in RUN_DIR as Ctrl-C would (for a run started in
                         the background or in another terminal); waits until it has stopped
  --out DIR              run folder (default runs/<preset>-<timestamp>, with -2, -3, ... added
                         when that is taken); a folder that exists must be empty
  --actors N             actor processes on this host (default: the preset's top-level
                         "actors = N", else 4)
  --num-actors N         actors in the whole run, for the Ape-X epsilons (default: --actors)
  --time-budget SECONDS  stop unsolved after this long (default 600)
  --goal SCORE           evaluation mean that ends the run (default: the preset's)
  --seed N               run seed (default 1)
  --ttl 0|1              LCM multicast TTL: 0 keeps traffic on this host, 1 reaches the LAN
                         (--slurm: 1)
  --port P               LCM port of the run (P, P+1 and P+2; default: three free random ones)
  --run-id ID            run id (default: random)
  --actor-args "..."     extra options for every actor, split at spaces (also --replay-args,
                         --learner-args, --evaluator-args)
  --record               record the run's main-port LCM traffic (stats, transitions,
                         evaluations, ...) with lcm-logger into RUN/lcm-log/: main.lcmlog.0 is
                         the newest file, older ones main.lcmlog.1 ... main.lcmlog.7
  --record-mb MB         size cap of the recording, in 8 files (default 256): past it the
                         oldest file goes
  --max-restarts N       restarts in a row of one process before it is down for good (default
                         5); the replay, learner or evaluator down for good ends the run
  --max-backoff SECONDS  the longest wait before a restart (default 10); the monitor ends a run
                         whose replay, learner or evaluator is silent for longer than this plus
                         the 30 s a process has to get ready, plus 5 s
  --reset-restarts-after SECONDS
                         a process that ran this long before it exited starts a new count of
                         restarts (default 300)
  --slurm                run inside a Slurm job (scripts/slurm.sbatch passes it): the replay,
                         learner and evaluator as steps on the job's first node (with the
                         monitor, the hubs and the recorder beside the launcher), actors as
                         steps on every node; a node lost leaves the run going on the others
  --actors-per-node N    (--slurm) actors on each node (default: the job's cores there, less
                         the replay, learner and evaluator on the first node)
  --transport udpm|tcp   (--slurm) LCM multicast (default), or LCM's TCP hub on the first node
                         for networks without multicast (java and Debian's liblcm-java)
  --or-resume            with --out DIR: when DIR holds a run, resume it (a requeued job);
                         --seed and --run-id, if given, must be the run's own
  --dry-run              check everything and print the run's processes and their command
                         lines; start nothing, create nothing
  --root DIR             the checkout: presets in DIR/configs, runs in DIR/runs (scripts/launch.sh
                         passes its own)
  --build-dir DIR        (scripts/launch.sh) where the binaries are built (default build)
  --no-setup             (scripts/launch.sh) do not install or build (use the binaries as they are)
)";
}

}  // namespace rl::launch
