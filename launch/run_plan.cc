#include "launch/run_plan.h"

#include <algorithm>
#include <charconv>
#include <cstdlib>

#include "common/text_format.h"
#include "launch/restart_policy.h"

namespace rl::launch {
namespace {

std::string Number(double v) { return FormatDouble("%.15g", v); }

std::string Joined(const std::vector<std::string>& words) {
  std::string s;
  for (const std::string& w : words) s += (s.empty() ? "" : " ") + w;
  return s;
}

// A process of one of our programs: BIN/KIND with the options every process takes.
PlannedProcess OurProcess(const RunPlan& plan, const std::string& role, const std::string& kind) {
  PlannedProcess p;
  p.role = role;
  p.kind = kind;
  p.argv = {plan.settings.bin_dir + "/" + kind};
  if (kind != "monitor") p.argv.insert(p.argv.end(), {"--config", plan.config_file});
  p.argv.insert(p.argv.end(), {"--run-id", std::to_string(plan.identity.run_id), "--key-file",
                               plan.key_file, "--lcm-url", plan.lcm_url, "--lcm-bulk-url",
                               plan.lcm_bulk_url, "--lcm-samples-url", plan.lcm_samples_url});
  p.log = plan.identity.run_dir + "/logs/" + role + ".log";
  p.ready = {Readiness::kLogLine, role + ": ready"};
  return p;
}

// Appends the user's extra options for the process's kind.
void AddExtra(const RunSettings& s, PlannedProcess* p) {
  const auto it = s.extra_args.find(p->kind);
  if (it != s.extra_args.end()) p->argv.insert(p->argv.end(), it->second.begin(), it->second.end());
}

}  // namespace

RunSettings ResolveSettings(const LaunchOptions& options, const Preset& preset,
                            const RunHeader* resumed, const std::string& bin_dir) {
  RunSettings s;
  s.resume = resumed != nullptr;
  s.preset = resumed != nullptr ? resumed->preset : options.preset;
  s.preset_path = preset.path();
  s.bin_dir = bin_dir;
  if (options.actors) {
    s.actors = *options.actors;
  } else if (resumed != nullptr) {
    s.actors = resumed->actors;
  } else if (const auto text = preset.Find("", "actors")) {
    int v = -1;
    const auto [end, ec] = std::from_chars(text->data(), text->data() + text->size(), v);
    if (ec != std::errc() || end != text->data() + text->size() || v < 0 || v > 4096) {
      throw LaunchError("preset " + preset.path() + ": actors must be a whole number from 0 to " +
                        "4096, not '" + *text + "'");
    }
    s.actors = v;
  }
  if (options.num_actors) {
    s.num_actors = *options.num_actors;
  } else if (resumed != nullptr) {
    s.num_actors = resumed->num_actors;
  } else {
    s.num_actors = std::max(s.actors, 1);
  }
  if (s.num_actors < s.actors) {
    throw LaunchError("--num-actors (" + std::to_string(s.num_actors) + ") must be at least the " +
                      std::to_string(s.actors) + " actors started here");
  }
  s.seed = options.seed.value_or(resumed != nullptr ? resumed->seed : 1);
  if (options.goal) {
    s.goal = *options.goal;
  } else if (const auto goal = preset.Find("evaluator", "goal")) {
    char* end = nullptr;
    std::strtod(goal->c_str(), &end);
    if (goal->empty() || end != goal->c_str() + goal->size()) {
      throw LaunchError("preset " + preset.path() + ": [evaluator] goal must be a number, not '" +
                        *goal + "'");
    }
    s.goal = *goal;
  } else {
    throw LaunchError("the preset has no [evaluator] goal; pass --goal");
  }
  s.time_budget = options.time_budget;
  s.ttl = options.ttl;
  s.transport = options.transport;
  s.record = options.record;
  s.record_mb = options.record_mb;
  s.extra_args = options.extra_args;
  s.limits = options.limits;
  return s;
}

std::string LcmUrl(int port, int ttl) {
  return "udpm://239.255.76.67:" + std::to_string(port) + "?ttl=" + std::to_string(ttl) +
         "&recv_buf_size=4194304";
}

std::string TcpHubUrl(const std::string& host, int port) {
  return "tcpq://" + host + ":" + std::to_string(port);
}

RunHeader RunPlan::Header(const std::string& started) const {
  RunHeader h;
  h.preset = settings.preset;
  h.started = started;
  h.run_id = identity.run_id;
  h.lcm_url = lcm_url;
  h.lcm_bulk_url = lcm_bulk_url;
  h.lcm_samples_url = lcm_samples_url;
  h.actors = settings.actors;
  h.num_actors = settings.num_actors;
  h.seed = settings.seed;
  h.goal = settings.goal;
  h.time_budget = settings.time_budget;
  if (!settings.extra_args.empty()) {
    for (const char* kind : {"actor", "replay", "learner", "evaluator"}) {
      const auto it = settings.extra_args.find(kind);
      h.extra += std::string(h.extra.empty() ? "" : " ") + kind + " [" +
                 (it == settings.extra_args.end() ? "" : Joined(it->second)) + "]";
    }
  }
  return h;
}

RunPlan BuildRunPlan(const RunSettings& settings, const RunIdentity& identity) {
  RunPlan plan;
  plan.settings = settings;
  plan.identity = identity;
  const bool tcp = settings.transport == "tcp";
  plan.lcm_url =
      tcp ? TcpHubUrl(settings.hub_host, identity.port) : LcmUrl(identity.port, settings.ttl);
  plan.lcm_bulk_url = tcp ? TcpHubUrl(settings.hub_host, identity.port + 1)
                          : LcmUrl(identity.port + 1, settings.ttl);
  plan.lcm_samples_url = tcp ? plan.lcm_bulk_url : LcmUrl(identity.port + 2, settings.ttl);
  const std::string& dir = identity.run_dir;
  plan.config_file = dir + "/config.ini";
  plan.key_file = dir + "/key";
  plan.monitor_silence = MonitorSilenceLimit(settings.limits);
  const std::string seed = std::to_string(settings.seed);

  for (int k = 0; tcp && k < 2; ++k) {
    // LCM's TCP hub (Debian's liblcm-java): one for each port, stateless, stopped last.
    PlannedProcess hub;
    hub.role = k == 0 ? "hub" : "hub-bulk";
    hub.kind = "hub";
    const std::string port = std::to_string(identity.port + k);
    hub.argv = {"java", "-cp", kLcmJar, "lcm.lcm.TCPService", port};
    hub.log = dir + "/logs/" + hub.role + ".log";
    hub.ready = {Readiness::kListens, port};
    hub.stops_last = true;
    plan.processes.push_back(hub);
  }

  if (settings.record) {
    // Rotating files of record_mb / 8 MB: main.lcmlog.0 is written, older ones are renamed up to
    // main.lcmlog.7 and the oldest deleted (a resumed run's recording moves up too). Quiet: no
    // line a second in its log. (Debian's 1.3.1 refuses the short form -l.)
    PlannedProcess p;
    p.role = p.kind = "recorder";
    const std::string file = dir + "/lcm-log/main.lcmlog";
    p.argv = {"lcm-logger",
              "--quiet",
              "--lcm-url=" + plan.lcm_url,
              "--rotate=8",
              "--split-mb=" + std::to_string(settings.record_mb / 8),
              file};
    p.log = dir + "/logs/recorder.log";
    p.ready = {Readiness::kOpensFile, file + ".0"};
    p.essential = false;
    p.stops_last = true;
    plan.processes.push_back(p);
  }

  PlannedProcess replay = OurProcess(plan, "replay", "replay");
  replay.argv.insert(replay.argv.end(),
                     {"--seed", seed, "--snapshot", dir + "/replay-snapshot.bin"});
  replay.writes_at_stop = dir;
  AddExtra(settings, &replay);
  plan.processes.push_back(replay);

  PlannedProcess learner = OurProcess(plan, "learner", "learner");
  learner.argv.insert(learner.argv.end(), {"--out", dir, "--seed", seed, "--resume"});
  learner.writes_at_stop = dir + "/checkpoints";
  AddExtra(settings, &learner);
  plan.processes.push_back(learner);

  PlannedProcess evaluator = OurProcess(plan, "evaluator", "evaluator");
  evaluator.argv.insert(evaluator.argv.end(),
                        {"--out", dir, "--goal", settings.goal, "--run-config", plan.config_file});
  AddExtra(settings, &evaluator);
  plan.processes.push_back(evaluator);

  for (int i = 0; i < settings.actors; ++i) {
    PlannedProcess actor = OurProcess(plan, "actor-" + std::to_string(i), "actor");
    actor.actor_id = i;
    actor.argv.insert(actor.argv.end(), {"--actor-id", std::to_string(i), "--num-actors",
                                         std::to_string(settings.num_actors), "--seed", seed});
    actor.essential = false;
    AddExtra(settings, &actor);
    plan.processes.push_back(actor);
  }

  // The monitor prints the progress line and decides when the run is over.
  PlannedProcess monitor = OurProcess(plan, "monitor", "monitor");
  monitor.argv.insert(
      monitor.argv.end(),
      {"--goal", settings.goal, "--time-budget", Number(settings.time_budget), "--metrics",
       dir + "/metrics.jsonl", "--restarts", dir + "/restarts", "--history", dir + "/eval.jsonl",
       "--stale-seconds", Number(plan.monitor_silence)});
  monitor.ready = {Readiness::kAtStart, ""};
  monitor.restart = false;
  monitor.ends_run = true;
  monitor.shown = true;
  plan.processes.push_back(monitor);
  return plan;
}

}  // namespace rl::launch
