#include "launch/run_plan.h"

#include <algorithm>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "launch/placement.h"
#include "launch/restart_policy.h"

namespace rl::launch {
namespace {

const char kPreset[] =
    "env = CartPole-v1\nactors = 3  # three\n[actor]\nn-step = 3\n[evaluator]\ngoal = 475 # g\n";

RunIdentity Identity() { return {"/runs/r", 77, 23456}; }

RunPlan Plan(const std::vector<std::string>& args, const RunHeader* resumed = nullptr) {
  const LaunchOptions o = ParseLaunchArgs(args);
  const Preset preset = Preset::Parse(kPreset, "/src/configs/cartpole.ini");
  return BuildRunPlan(ResolveSettings(o, preset, resumed, "/bin"), Identity());
}

const PlannedProcess& Find(const RunPlan& plan, const std::string& role) {
  for (const PlannedProcess& p : plan.processes) {
    if (p.role == role) return p;
  }
  throw std::runtime_error("no " + role);
}

// The value after `option` in `argv`, or "" when it is not there.
std::string ValueOf(const std::vector<std::string>& argv, const std::string& option) {
  const auto it = std::find(argv.begin(), argv.end(), option);
  return it == argv.end() || it + 1 == argv.end() ? "" : *(it + 1);
}

bool Has(const std::vector<std::string>& argv, const std::string& word) {
  return std::find(argv.begin(), argv.end(), word) != argv.end();
}

TEST(RunPlanTest, ProcessesStartInOrderWithTheirLogsAndReadiness) {
  const RunPlan plan = Plan({"cartpole"});
  std::vector<std::string> roles;
  for (const PlannedProcess& p : plan.processes) roles.push_back(p.role);
  EXPECT_EQ(roles, (std::vector<std::string>{"replay", "learner", "evaluator", "actor-0", "actor-1",
                                             "actor-2", "monitor"}));
  const PlannedProcess& replay = Find(plan, "replay");
  EXPECT_EQ(replay.argv[0], "/bin/replay");
  EXPECT_EQ(replay.log, "/runs/r/logs/replay.log");
  EXPECT_EQ(replay.ready.kind, Readiness::kLogLine);
  EXPECT_EQ(replay.ready.text, "replay: ready");
  EXPECT_TRUE(replay.essential);
  EXPECT_TRUE(replay.restart);
  EXPECT_EQ(Find(plan, "actor-2").ready.text, "actor-2: ready");
  EXPECT_FALSE(Find(plan, "actor-2").essential);
  const PlannedProcess& monitor = Find(plan, "monitor");
  EXPECT_TRUE(monitor.ends_run);
  EXPECT_TRUE(monitor.shown);
  EXPECT_FALSE(monitor.restart);
  EXPECT_EQ(monitor.log, "/runs/r/logs/monitor.log");
  // It starts from the run's evaluations, so that a resumed run shows the best of all its parts.
  EXPECT_EQ(ValueOf(monitor.argv, "--history"), "/runs/r/eval.jsonl");
}

TEST(RunPlanTest, EveryProcessGetsTheRunsIdentity) {
  const RunPlan plan = Plan({"cartpole"});
  EXPECT_EQ(plan.lcm_url, "udpm://239.255.76.67:23456?ttl=0&recv_buf_size=4194304");
  EXPECT_EQ(plan.lcm_bulk_url, "udpm://239.255.76.67:23457?ttl=0&recv_buf_size=4194304");
  EXPECT_EQ(plan.lcm_samples_url, "udpm://239.255.76.67:23458?ttl=0&recv_buf_size=4194304");
  for (const PlannedProcess& p : plan.processes) {
    EXPECT_EQ(ValueOf(p.argv, "--run-id"), "77") << p.role;
    EXPECT_EQ(ValueOf(p.argv, "--key-file"), "/runs/r/key") << p.role;
    EXPECT_EQ(ValueOf(p.argv, "--lcm-url"), plan.lcm_url) << p.role;
    EXPECT_EQ(ValueOf(p.argv, "--lcm-bulk-url"), plan.lcm_bulk_url) << p.role;
    EXPECT_EQ(ValueOf(p.argv, "--lcm-samples-url"), plan.lcm_samples_url) << p.role;
    // The monitor reads no preset; every other process the run's copy of it.
    EXPECT_EQ(ValueOf(p.argv, "--config"), p.role == "monitor" ? "" : "/runs/r/config.ini");
  }
}

TEST(RunPlanTest, ActorsHaveTheirIdsAndTheRunsSeedAndCount) {
  const RunPlan plan = Plan({"cartpole", "--actors", "2", "--num-actors", "5", "--seed", "9"});
  EXPECT_EQ(plan.settings.actors, 2);
  EXPECT_EQ(plan.settings.num_actors, 5);
  for (int i = 0; i < 2; ++i) {
    const PlannedProcess& a = Find(plan, "actor-" + std::to_string(i));
    EXPECT_EQ(a.actor_id, i);
    EXPECT_EQ(ValueOf(a.argv, "--actor-id"), std::to_string(i));
    EXPECT_EQ(ValueOf(a.argv, "--num-actors"), "5");
    EXPECT_EQ(ValueOf(a.argv, "--seed"), "9");
  }
  EXPECT_EQ(ValueOf(Find(plan, "replay").argv, "--seed"), "9");
  EXPECT_EQ(ValueOf(Find(plan, "learner").argv, "--seed"), "9");
}

TEST(RunPlanTest, ThePresetGivesActorsAndGoalUnlessTheCommandLineDoes) {
  RunPlan plan = Plan({"cartpole"});
  EXPECT_EQ(plan.settings.actors, 3);  // "actors = 3  # three": the comment is no part of it
  EXPECT_EQ(plan.settings.num_actors, 3);
  EXPECT_EQ(plan.settings.goal, "475");
  EXPECT_EQ(ValueOf(Find(plan, "evaluator").argv, "--goal"), "475");
  EXPECT_EQ(ValueOf(Find(plan, "monitor").argv, "--goal"), "475");
  plan = Plan({"cartpole", "--goal", "-250", "--actors", "1"});
  EXPECT_EQ(ValueOf(Find(plan, "evaluator").argv, "--goal"), "-250");
  EXPECT_EQ(plan.processes.size(), 5u);
}

TEST(RunPlanTest, LearnerResumesAndReplayKeepsItsSnapshotAlways) {
  const RunPlan plan = Plan({"cartpole"});
  const PlannedProcess& learner = Find(plan, "learner");
  EXPECT_TRUE(Has(learner.argv, "--resume"));
  EXPECT_EQ(ValueOf(learner.argv, "--out"), "/runs/r");
  EXPECT_EQ(ValueOf(Find(plan, "replay").argv, "--snapshot"), "/runs/r/replay-snapshot.bin");
  // Where they write as they stop, which a stop waits for while it grows.
  EXPECT_EQ(Find(plan, "replay").writes_at_stop, "/runs/r");
  EXPECT_EQ(learner.writes_at_stop, "/runs/r/checkpoints");
  const PlannedProcess& evaluator = Find(plan, "evaluator");
  EXPECT_EQ(evaluator.writes_at_stop, "");
  EXPECT_EQ(ValueOf(evaluator.argv, "--out"), "/runs/r");
  EXPECT_EQ(ValueOf(evaluator.argv, "--run-config"), "/runs/r/config.ini");
}

TEST(RunPlanTest, ExtraArgumentsGoToTheirKindLast) {
  const RunPlan plan =
      Plan({"cartpole", "--actor-args", "--stats-hz 2", "--learner-args", "--threads 1"});
  for (const std::string role : {"actor-0", "actor-1", "actor-2"}) {
    const std::vector<std::string>& argv = Find(plan, role).argv;
    ASSERT_GE(argv.size(), 2u);
    EXPECT_EQ(argv[argv.size() - 2], "--stats-hz");
    EXPECT_EQ(argv.back(), "2");
  }
  EXPECT_EQ(Find(plan, "learner").argv.back(), "1");
  EXPECT_FALSE(Has(Find(plan, "replay").argv, "--stats-hz"));
  EXPECT_EQ(plan.Header("t").extra,
            "actor [--stats-hz 2] replay [] learner [--threads 1] evaluator []");
}

TEST(RunPlanTest, ARecordedRunStartsItsRecorderFirstAndStopsItLast) {
  const RunPlan plan = Plan({"cartpole", "--record", "--record-mb", "64"});
  const PlannedProcess& recorder = plan.processes.front();
  EXPECT_EQ(recorder.role, "recorder");
  EXPECT_EQ(recorder.argv, (std::vector<std::string>{
                               "lcm-logger", "--quiet", "--lcm-url=" + plan.lcm_url, "--rotate=8",
                               "--split-mb=8", "/runs/r/lcm-log/main.lcmlog"}));
  EXPECT_EQ(recorder.ready.kind, Readiness::kOpensFile);
  EXPECT_EQ(recorder.ready.text, "/runs/r/lcm-log/main.lcmlog.0");
  EXPECT_TRUE(recorder.stops_last);
  EXPECT_FALSE(recorder.essential);
}

TEST(RunPlanTest, TheMonitorsSilenceLimitComesFromTheRestartLimits) {
  const RunPlan plan = Plan({"cartpole", "--max-backoff", "20", "--time-budget", "90"});
  EXPECT_DOUBLE_EQ(plan.monitor_silence, MonitorSilenceLimit(plan.settings.limits));
  const PlannedProcess& monitor = Find(plan, "monitor");
  EXPECT_EQ(ValueOf(monitor.argv, "--stale-seconds"), "55");  // 20 + 30 + 5
  EXPECT_EQ(ValueOf(monitor.argv, "--time-budget"), "90");
  EXPECT_EQ(ValueOf(monitor.argv, "--restarts"), "/runs/r/restarts");
  EXPECT_EQ(ValueOf(monitor.argv, "--metrics"), "/runs/r/metrics.jsonl");
}

TEST(RunPlanTest, AResumedRunKeepsItsOwnActorsSeedAndPresetName) {
  RunHeader header;
  header.preset = "lunar_lander";
  header.run_id = 77;
  header.actors = 2;
  header.num_actors = 6;
  header.seed = 4;
  header.goal = "100000";  // the first launch's goal: a resumed run takes the preset's
  RunPlan plan = Plan({"--resume", "/runs/r", "--time-budget", "30"}, &header);
  EXPECT_TRUE(plan.settings.resume);
  EXPECT_EQ(plan.settings.preset, "lunar_lander");
  EXPECT_EQ(plan.settings.actors, 2);
  EXPECT_EQ(plan.settings.num_actors, 6);
  EXPECT_EQ(plan.settings.seed, 4u);
  EXPECT_EQ(plan.settings.goal, "475");
  EXPECT_EQ(ValueOf(Find(plan, "actor-1").argv, "--num-actors"), "6");
  EXPECT_EQ(ValueOf(Find(plan, "actor-1").argv, "--seed"), "4");
  // Fewer actors this time: the run's count (and so each actor's epsilon) stays.
  plan = Plan({"--resume", "/runs/r", "--actors", "1"}, &header);
  EXPECT_EQ(plan.settings.actors, 1);
  EXPECT_EQ(plan.settings.num_actors, 6);
  // More actors than the run has is an error, not a silent change of every epsilon.
  EXPECT_THROW(Plan({"--resume", "/runs/r", "--actors", "7"}, &header), LaunchError);
}

TEST(RunPlanTest, ABadActorsOrNoGoalInThePresetIsAnError) {
  const LaunchOptions o = ParseLaunchArgs({"cartpole"});
  EXPECT_THROW(ResolveSettings(o, Preset::Parse("actors = two\n[evaluator]\ngoal = 1\n", "p"),
                               nullptr, "/bin"),
               LaunchError);
  EXPECT_THROW(ResolveSettings(o, Preset::Parse("env = CartPole-v1\n", "p"), nullptr, "/bin"),
               LaunchError);
}

TEST(RunPlanTest, LocalPlacementRunsTheArgvAsPlanned) {
  const RunPlan plan = Plan({"cartpole"});
  const LocalPlacement local;
  for (const PlannedProcess& p : plan.processes) EXPECT_EQ(local.Command(p), p.argv);
}

}  // namespace
}  // namespace rl::launch
