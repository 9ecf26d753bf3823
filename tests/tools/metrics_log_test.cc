#include "tools/metrics_log.h"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "evaluator/json_line.h"
#include "tests/common/temp_dir.h"

namespace rl::tools {
namespace {

namespace fs = std::filesystem;

std::vector<std::string> Lines(const fs::path& path) {
  std::ifstream in(path);
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

TEST(MetricsLineTest, WritesOneJsonObjectPerRoleWithTheStatsFields) {
  rlmsg::stats_learner_t learner{};
  learner.header.sender = "learner";
  learner.updates = 5000;
  learner.loss = 0.25;
  learner.mean_q = std::numeric_limits<double>::quiet_NaN();
  learner.lost = 2;
  learner.dropped_invalid = 3;
  learner.dropped_replayed = 4;  // counted in "dropped" and on its own
  EXPECT_EQ(MetricsLine(12.5, learner),
            "{\"t\": 12.5, \"role\": \"learner\", \"updates\": 5000, \"updates_per_second\": 0.0, "
            "\"loss\": 0.25, \"mean_q\": null, \"env_steps\": 0, \"weights_version\": 0, "
            "\"lost\": 2, \"dropped\": 7, \"replayed\": 4, \"unauthenticated\": 0, "
            "\"age\": 0.0}\n");
  // The age of a message the row repeats, in tenths of a second.
  EXPECT_NE(MetricsLine(12.5, learner, 46.04).find("\"age\": 46.0}"), std::string::npos);
  rlmsg::stats_actor_t actor{};
  actor.header.sender = "actor-3";
  actor.env_steps = 1234567;
  actor.epsilon = 0.1;
  const std::string a = MetricsLine(1, actor);
  EXPECT_EQ(a.rfind("{\"t\": 1.0, \"role\": \"actor-3\", \"env_steps\": 1234567,", 0), 0u) << a;
  EXPECT_NE(a.find("\"exploration\": 0.1,"), std::string::npos) << a;
  rlmsg::stats_replay_t replay{};
  replay.header.sender = "replay";
  replay.size = 7;
  EXPECT_NE(MetricsLine(1, replay).find("\"size\": 7,"), std::string::npos);
  rlmsg::stats_evaluator_t evaluator{};
  evaluator.header.sender = "evaluator";
  evaluator.best_mean = -150.5;
  EXPECT_NE(MetricsLine(1, evaluator).find("\"best_mean\": -150.5,"), std::string::npos);
}

TEST(MetricsLineTest, LinesReadBackAsJsonWithTenSignificantDigits) {
  rlmsg::stats_actor_t actor{};
  actor.header.sender = "actor-0";
  actor.steps_per_second = 1234.567890123456;
  actor.mean_return = 1.0 / 3.0;
  const std::string line = MetricsLine(3.0004, actor);
  EXPECT_NE(line.find("\"mean_return\": 0.3333333333,"), std::string::npos) << line;
  const std::optional<nlohmann::json> back = ParseJsonLine(line);
  ASSERT_TRUE(back.has_value()) << line;
  EXPECT_EQ(JsonNumberAt(*back, "t"), 3.0);  // milliseconds
  EXPECT_EQ(JsonNumberAt(*back, "steps_per_second"), 1234.56789);
  EXPECT_EQ(JsonStringAt(*back, "role"), "actor-0");
  EXPECT_EQ(JsonIntegerAt(*back, "paused"), 0);
}

// `path_` names a file that does not exist yet, in a directory of the test's own.
class MetricsLogTest : public TempDirTest {
 protected:
  const fs::path path_ = dir_ / "metrics.jsonl";
};

TEST_F(MetricsLogTest, RowsFollowTheScheduleAndAppendAfterARestart) {
  {
    MetricsLog log(path_.string(), /*dense_seconds=*/10, /*dense_period=*/1,
                   /*sparse_period=*/5);
    EXPECT_EQ(log.last_t(), 0);  // a new file
    int rows = 0;
    for (double t = 0; t < 30; t += 0.25) {
      if (!log.Due(t)) continue;
      log.AppendRow(t, "{\"t\": " + std::to_string(t) + "}\n");
      ++rows;
    }
    // Every second for 10 s (t = 0..9), then every 5 s (10, 15, 20, 25).
    EXPECT_EQ(rows, 14);
    EXPECT_EQ(log.rows(), 14);
  }
  {
    MetricsLog again(path_.string());
    EXPECT_EQ(again.last_t(), 25);  // the last row's: a resumed run's rows carry on from it
    again.AppendRow(31, "{\"t\": 31}\n");
  }
  const std::vector<std::string> lines = Lines(path_);
  ASSERT_EQ(lines.size(), 15u);
  EXPECT_EQ(lines.back(), "{\"t\": 31}");
}

TEST_F(MetricsLogTest, TheLastTPassesOverLinesThatAreNotWholeRows) {
  {
    std::ofstream out(path_);
    out << "{\"t\": 7.5, \"role\": \"learner\"}\n"
        << "{\"t\": 8.5, \"role\": \"replay\"}\n"
        << "{\"role\": \"actor-0\"}\n"  // no t
        << "not json\n"
        << "{\"t\": 9.5, \"role\": \"lear";  // cut short
  }
  EXPECT_EQ(MetricsLog(path_.string()).last_t(), 8.5);
}

TEST_F(MetricsLogTest, ActorEpisodesCountEveryLifeOfEveryActor) {
  EXPECT_EQ(ActorEpisodes(path_.string()), 0);  // no file: a new run
  {
    std::ofstream out(path_);
    out << "{\"t\": 1, \"role\": \"actor-0\", \"episodes\": 5}\n"
        << "{\"t\": 1, \"role\": \"actor-1\", \"episodes\": 3}\n"
        << "{\"t\": 1, \"role\": \"evaluator\", \"episodes\": 100}\n"  // not an actor's
        << "{\"t\": 2, \"role\": \"actor-0\", \"episodes\": 9}\n"
        << "{\"t\": 3, \"role\": \"actor-0\", \"episodes\": 2}\n"  // restarted after 9
        << "not json\n"
        << "{\"t\": 4, \"role\": \"actor-0\", \"episodes\": 4}\n"
        << "{\"t\": 4, \"role\": \"actor-1\", \"episodes\": 7}\n"
        << "{\"t\": 5, \"role\": \"actor-1\", \"epis";  // cut short
  }
  EXPECT_EQ(ActorEpisodes(path_.string()), 9 + 4 + 7);
}

TEST_F(MetricsLogTest, AnUnwritablePathIsRefusedWithItsName) {
  const std::string bad = (path_.parent_path() / "no_such_dir" / "m.jsonl").string();
  try {
    MetricsLog log(bad);
    FAIL() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(bad), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace rl::tools
