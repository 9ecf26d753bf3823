// monitor: the live view of a run for the launch script.
//
// Listens to every process's stats and the evaluator's results, prints a progress line, and
// exits when the run is over: 0 when an evaluation reached the goal, 1 when the time budget ran
// out, 3 when the replay, the learner or the evaluator went silent, 130 on SIGINT/SIGTERM. With
// --metrics FILE it also appends the stats of every process to FILE as a time series
// (tools/metrics_log.h), and a resumed run's episode count starts from the file's; with --history
// FILE (the run's eval.jsonl) a resumed run's progress line starts from the evaluations of its
// earlier parts.
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "common/channels.h"
#include "common/clock.h"
#include "common/options.h"
#include "common/shutdown.h"
#include "common/text_format.h"
#include "evaluator/eval_history.h"
#include "rlmsg/eval_result_t.hpp"
#include "rlmsg/stats_actor_t.hpp"
#include "rlmsg/stats_evaluator_t.hpp"
#include "rlmsg/stats_learner_t.hpp"
#include "rlmsg/stats_replay_t.hpp"
#include "tools/metrics_log.h"

namespace {

using rl::Score;
using rl::Thousands;

struct View {
  std::map<std::string, rlmsg::stats_actor_t> actors;  // by sender
  std::map<std::string, double> actor_seen;
  // The largest step count each actor showed: a restarted actor takes its count up from the
  // replay (actor/actor.h), which may lack the batch it had on the way when it died, so the
  // total never goes back.
  std::map<std::string, int64_t> actor_steps;
  // Episodes of the actors' earlier lives: those of a resumed run's earlier parts (from its
  // metrics file) and those of an actor restarted since, whose count starts again at 0.
  int64_t earlier_episodes = 0;
  rlmsg::stats_replay_t replay{};
  rlmsg::stats_learner_t learner{};
  rlmsg::stats_evaluator_t evaluator{};
  double replay_seen = 0, learner_seen = 0, evaluator_seen = 0;
  bool have_eval = false;
  rlmsg::eval_result_t last_eval{};
  double best_eval = -1e300;
  bool goal_reached = false;
};

// The lines of one metrics row: the newest stats of every role heard from.
std::string MetricsRow(const View& v, double t, double now) {
  std::string lines;
  for (const auto& [sender, s] : v.actors) {
    lines += rl::tools::MetricsLine(t, s, now - v.actor_seen.at(sender));
  }
  if (v.replay_seen > 0) lines += rl::tools::MetricsLine(t, v.replay, now - v.replay_seen);
  if (v.learner_seen > 0) lines += rl::tools::MetricsLine(t, v.learner, now - v.learner_seen);
  if (v.evaluator_seen > 0) {
    lines += rl::tools::MetricsLine(t, v.evaluator, now - v.evaluator_seen);
  }
  return lines;
}

// Lines of the launch script's restarts file (one per restarted process); 0 when there is none.
int64_t CountRestarts(const std::string& path) {
  if (path.empty()) return 0;
  std::ifstream in(path);
  int64_t n = 0;
  for (std::string line; std::getline(in, line);) n += !line.empty();
  return n;
}

// Starts the view's evaluations from the run's history: the last one scored and the best.
void LoadHistory(const std::string& path, View* v) {
  int skipped = 0;
  const std::vector<rl::evaluator::EvalRecord> records =
      rl::evaluator::LoadJsonLines(path, &skipped);
  if (skipped > 0) {
    std::fprintf(stderr, "monitor: %d unreadable lines in %s\n", skipped, path.c_str());
  }
  if (records.empty()) return;
  v->have_eval = true;
  v->last_eval.mean = records.back().mean;
  v->last_eval.std = records.back().std;
  for (const rl::evaluator::EvalRecord& r : records) v->best_eval = std::max(v->best_eval, r.mean);
}

std::string ProgressLine(const View& v, double elapsed, double now, int64_t restarts = 0) {
  int64_t steps = 0, episodes = v.earlier_episodes, lost = 0, dropped = 0;
  double ret = 0;
  int live = 0, paused = 0;
  for (const auto& [name, a] : v.actors) {
    steps += v.actor_steps.at(name);
    episodes += a.episodes;
    lost += a.lost;
    dropped += rl::Dropped(a);
    if (now - v.actor_seen.at(name) < 3.0) {
      ++live;
      ret += a.mean_return;
      paused += a.paused;
    }
  }
  lost += v.replay.lost + v.learner.lost + v.evaluator.lost;
  dropped += rl::Dropped(v.replay) + rl::Dropped(v.learner) + rl::Dropped(v.evaluator);
  std::string eval = "eval -";
  if (v.have_eval) {
    eval = "eval " + Score(v.last_eval.mean) + " (best " + Score(v.best_eval) + ")";
  }
  char line[512];
  std::snprintf(line, sizeof(line),
                "[%6.1fs] steps %s  episodes %s  return %s  %s  learner %.0f upd/s (%s)  "
                "replay %s  actors %d%s  lost %lld  dropped %lld",
                elapsed, Thousands(steps).c_str(), Thousands(episodes).c_str(),
                Score(live > 0 ? ret / live : 0.0).c_str(), eval.c_str(),
                v.learner.updates_per_second, Thousands(v.learner.updates).c_str(),
                Thousands(v.replay.size).c_str(), live, paused > 0 ? " (paused)" : "",
                static_cast<long long>(lost), static_cast<long long>(dropped));
  if (restarts > 0) return std::string(line) + "  restarts " + std::to_string(restarts);
  return line;
}

int Main(int argc, char** argv) {
  rl::CommonOptions common;
  double goal = 475;
  double time_budget = 600;
  double stale_seconds = 20;
  double print_seconds = 1;
  std::string metrics_path;
  std::string restarts_path;
  std::string history_path;
  rl::po::options_description desc("Options");
  rl::AddCommonOptions(&desc, &common);
  desc.add_options()                                                                            //
      ("goal", rl::po::value(&goal)->default_value(goal), "evaluation mean that ends the run")  //
      ("time-budget", rl::po::value(&time_budget)->default_value(time_budget),
       "seconds after which the run ends unsolved")  //
      ("stale-seconds", rl::po::value(&stale_seconds)->default_value(stale_seconds),
       "a replay, learner or evaluator silent this long ends the run (the launcher passes its "
       "longest restart backoff plus the time a restarted process has to get ready, plus 5 s, "
       "so that a process being restarted is not taken for one that hangs)")  //
      ("print-seconds", rl::po::value(&print_seconds)->default_value(print_seconds),
       "seconds between progress lines")  //
      ("metrics", rl::po::value(&metrics_path),
       "append every process's stats to this file as JSON lines (a row a second for the first "
       "hour, then every 10 s); the progress line's episodes count on from its rows")  //
      ("restarts", rl::po::value(&restarts_path),
       "the launch script's file of restarted processes (a line each): their count joins the "
       "progress line")  //
      ("history", rl::po::value(&history_path),
       "the run's evaluation history (eval.jsonl): the progress line's last and best evaluation "
       "start from it, so that a resumed run shows the best of all its parts");
  rl::po::variables_map vm;
  if (!rl::ParseOptions(argc, argv, "monitor",
                        "Usage: monitor [options]\n"
                        "Shows a run's progress from its stats messages and exits when the goal is "
                        "reached (0), the time budget is spent (1) or a process went silent (3).",
                        desc, &vm)) {
    return 0;
  }
  rl::InstallStopHandlers();
  std::unique_ptr<rl::tools::MetricsLog> metrics;
  View v;
  if (!metrics_path.empty()) {
    v.earlier_episodes = rl::tools::ActorEpisodes(metrics_path);
    metrics = std::make_unique<rl::tools::MetricsLog>(metrics_path);
  }
  rl::Bus bus(common.MakeBusConfig("monitor"));
  if (!history_path.empty()) LoadHistory(history_path, &v);
  bus.Subscribe<rlmsg::stats_actor_t>(
      rl::channels::kStatsActor, [&v](const rlmsg::stats_actor_t& s) {
        const auto known = v.actors.find(s.header.sender);
        if (known != v.actors.end() && s.episodes < known->second.episodes) {
          v.earlier_episodes += known->second.episodes;
        }
        v.actors[s.header.sender] = s;
        v.actor_seen[s.header.sender] = rl::MonoSeconds();
        int64_t& steps = v.actor_steps[s.header.sender];
        steps = std::max(steps, s.env_steps);
      });
  bus.Subscribe<rlmsg::stats_replay_t>(rl::channels::kStatsReplay,
                                       [&v](const rlmsg::stats_replay_t& s) {
                                         v.replay = s;
                                         v.replay_seen = rl::MonoSeconds();
                                       });
  bus.Subscribe<rlmsg::stats_learner_t>(rl::channels::kStatsLearner,
                                        [&v](const rlmsg::stats_learner_t& s) {
                                          v.learner = s;
                                          v.learner_seen = rl::MonoSeconds();
                                        });
  bus.Subscribe<rlmsg::stats_evaluator_t>(rl::channels::kStatsEvaluator,
                                          [&v](const rlmsg::stats_evaluator_t& s) {
                                            v.evaluator = s;
                                            v.evaluator_seen = rl::MonoSeconds();
                                          });
  bus.Subscribe<rlmsg::eval_result_t>(rl::channels::kEval, [&](const rlmsg::eval_result_t& e) {
    v.have_eval = true;
    v.last_eval = e;
    v.best_eval = std::max(v.best_eval, e.mean);
    std::printf("evaluation: update %lld, env steps %lld: mean %s +- %s over %d episodes%s\n",
                static_cast<long long>(e.update), static_cast<long long>(e.env_steps),
                Score(e.mean).c_str(), Score(e.std).c_str(), e.episodes,
                e.mean >= goal ? " -- goal reached" : "");
    std::fflush(stdout);
    if (e.mean >= goal) v.goal_reached = true;
  });
  std::printf("monitor: ready\n");
  std::fflush(stdout);

  const bool tty = isatty(STDOUT_FILENO) != 0;
  const double start = rl::MonoSeconds();
  double next_print = start + print_seconds;
  int status = 1;
  while (true) {
    bus.Handle(100);
    const double now = rl::MonoSeconds();
    const double elapsed = now - start;
    if (v.goal_reached) {
      status = 0;
      break;
    }
    if (rl::StopRequested()) {
      status = 130;
      break;
    }
    if (elapsed >= time_budget) {
      std::printf("\nmonitor: time budget of %.0f s spent\n", time_budget);
      status = 1;
      break;
    }
    const char* silent = nullptr;
    if (v.replay_seen > 0 && now - v.replay_seen > stale_seconds) silent = "replay";
    if (v.learner_seen > 0 && now - v.learner_seen > stale_seconds) silent = "learner";
    if (v.evaluator_seen > 0 && now - v.evaluator_seen > stale_seconds) silent = "evaluator";
    if (silent != nullptr) {
      std::printf("\nmonitor: the %s has been silent for %.0f s\n", silent, stale_seconds);
      status = 3;
      break;
    }
    // A resumed run's rows carry on from the earlier parts' (MetricsLog::last_t).
    if (metrics != nullptr && metrics->Due(metrics->last_t() + elapsed)) {
      const double t = metrics->last_t() + elapsed;
      const std::string row = MetricsRow(v, t, now);
      if (!row.empty()) metrics->AppendRow(t, row);
    }
    if (now >= next_print) {
      std::printf(tty ? "\r%s\033[K" : "%s\n",
                  ProgressLine(v, elapsed, now, CountRestarts(restarts_path)).c_str());
      std::fflush(stdout);
      next_print = now + print_seconds;
    }
  }
  std::printf(
      "%s%s\n", tty ? "\r" : "",
      ProgressLine(v, rl::MonoSeconds() - start, rl::MonoSeconds(), CountRestarts(restarts_path))
          .c_str());
  return status;
}

}  // namespace

int main(int argc, char** argv) { return rl::RunMain("monitor", Main, argc, argv); }
