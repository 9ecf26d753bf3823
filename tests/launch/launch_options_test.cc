#include "launch/launch_options.h"

#include <string>
#include <vector>

#include <gtest/gtest.h>

namespace rl::launch {
namespace {

// The error ParseLaunchArgs gives for `args`, or "" when it accepts them.
std::string ErrorOf(const std::vector<std::string>& args) {
  try {
    ParseLaunchArgs(args);
  } catch (const LaunchError& e) {
    return e.what();
  }
  return "";
}

TEST(LaunchOptionsTest, ReadsEveryOptionOfARun) {
  const LaunchOptions o = ParseLaunchArgs({"cartpole",
                                           "--out",
                                           "runs/x",
                                           "--actors",
                                           "2",
                                           "--num-actors",
                                           "6",
                                           "--time-budget",
                                           "90.5",
                                           "--goal",
                                           "-250",
                                           "--seed",
                                           "7",
                                           "--ttl",
                                           "1",
                                           "--port",
                                           "7667",
                                           "--run-id",
                                           "42",
                                           "--actor-args",
                                           " --stats-hz 2  --max-steps 9",
                                           "--record",
                                           "--record-mb",
                                           "16",
                                           "--max-restarts",
                                           "3",
                                           "--max-backoff",
                                           "4",
                                           "--reset-restarts-after",
                                           "60"});
  EXPECT_EQ(o.mode, Mode::kRun);
  EXPECT_EQ(o.preset, "cartpole");
  EXPECT_EQ(o.out, "runs/x");
  EXPECT_EQ(o.actors, 2);
  EXPECT_EQ(o.num_actors, 6);
  EXPECT_DOUBLE_EQ(o.time_budget, 90.5);
  EXPECT_EQ(o.goal, "-250");
  EXPECT_EQ(o.seed, 7u);
  EXPECT_EQ(o.ttl, 1);
  EXPECT_EQ(o.port, 7667);
  EXPECT_EQ(o.run_id, 42);
  EXPECT_EQ(o.extra_args.at("actor"),
            (std::vector<std::string>{"--stats-hz", "2", "--max-steps", "9"}));
  EXPECT_TRUE(o.record);
  EXPECT_EQ(o.record_mb, 16);
  EXPECT_EQ(o.limits.max_restarts, 3);
  EXPECT_DOUBLE_EQ(o.limits.max_backoff, 4);
  EXPECT_DOUBLE_EQ(o.limits.reset_after, 60);
}

TEST(LaunchOptionsTest, ResumeAndStopTakeARunFolder) {
  LaunchOptions o = ParseLaunchArgs({"--resume", "runs/a", "--time-budget", "30"});
  EXPECT_EQ(o.mode, Mode::kResume);
  EXPECT_EQ(o.run_dir, "runs/a");
  o = ParseLaunchArgs({"--stop", "runs/a"});
  EXPECT_EQ(o.mode, Mode::kStop);
  EXPECT_EQ(ErrorOf({"--stop", "runs/a", "--seed", "1"}),
            "--stop takes a run folder and nothing else");
  EXPECT_EQ(ErrorOf({"--resume", "runs/a", "--seed", "2"}),
            "--seed cannot change a resumed run's seed");
  EXPECT_EQ(ErrorOf({"--resume", "runs/a", "--out", "b"}),
            "--out cannot change a resumed run's folder");
  EXPECT_EQ(ErrorOf({"--resume"}), "--resume needs a run folder");
}

TEST(LaunchOptionsTest, RefusesNumbersThatAreNoneOrOutOfRange) {
  // Each option, what it takes, and values it refuses with "<option> must be <what it takes>, not
  // '<value>'".
  const struct {
    std::string option;
    std::string takes;
    std::vector<std::string> refused;
  } cases[] = {
      {"--time-budget", "a positive number of seconds", {"-5", "0", "ten", "nan"}},
      {"--actors", "a whole number from 0 to 4096", {"-1", "2x"}},
      {"--seed", "a whole number", {"1.5"}},
      {"--goal", "a number (an evaluation mean)", {"high"}},
      {"--ttl", "0 or 1", {"2"}},
      {"--port", "a UDP port from 1024 to 65533 (P, P+1 and P+2)", {"65534"}},
      {"--record-mb", "a whole number of at least 8", {"4"}},
      {"--max-backoff", "a positive number of seconds", {"-1"}},
  };
  for (const auto& c : cases) {
    for (const std::string& value : c.refused) {
      EXPECT_EQ(ErrorOf({"cartpole", c.option, value}),
                c.option + " must be " + c.takes + ", not '" + value + "'");
    }
  }
  EXPECT_EQ(ErrorOf({"cartpole", "--actors", "4", "--num-actors", "2"}),
            "--num-actors (2) must be at least --actors (4)");
}

TEST(LaunchOptionsTest, RefusesUnknownOptionsAndMissingValues) {
  EXPECT_EQ(ErrorOf({"cartpole", "--acters", "2"}), "unknown option '--acters' (see --help)");
  EXPECT_EQ(ErrorOf({"cartpole", "--seed"}), "--seed needs a value (see --help)");
  EXPECT_EQ(ErrorOf({"cartpole", "extra"}), "unexpected argument 'extra' (see --help)");
  EXPECT_EQ(ErrorOf({}), "no preset given (see --help)");
  EXPECT_EQ(ParseLaunchArgs({"cartpole", "--help"}).mode, Mode::kHelp);
}

}  // namespace
}  // namespace rl::launch
