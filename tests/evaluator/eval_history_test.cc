#include "evaluator/eval_history.h"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "file_helpers.h"
#include "sample_record.h"
#include "tests/common/read_file.h"
#include "tests/common/temp_dir.h"

namespace rl::evaluator {
namespace {

// A record with plausible numbers.
constexpr auto& Record = testing::SampleRecord;

TEST(JsonLinesTest, TwoAppendedRecordsReadBackEqual) {
  TempDir dir;
  const std::string path = dir / "eval.jsonl";
  EvalRecord a = Record("ckpt_000001000.bin", 1000, 1.0 / 3.0);
  a.wall_seconds = 0.1;
  EvalRecord b = Record("odd \"name\" \\ tab\t\xC3\xA9.bin", 2000, 475.25);
  b.min = -1e-300;
  // With value estimates, one of them without a correlation (written as null).
  EvalRecord c = Record("c.bin", 3000, 0.36);
  c.value_steps = 1234;
  c.value_estimate = 0.291;
  c.value_return = 0.2705;
  c.value_correlation = -0.125;
  EvalRecord d = c;
  d.value_correlation.reset();
  // With a second metric.
  d.second_episodes = 100;
  d.second_mean = 642.125;
  d.second_std = -0.5;
  // With the episodes' returns.
  d.returns = {-0.1, 912.5, 1.0 / 3.0};
  d.steps = {1, 200, 0};
  d.action_mean = {0.25, -0.5, 0.125};
  // With an ensemble's score.
  EvalRecord e = Record("e.bin", 5000, 800.5);
  e.ensemble_size = 5;
  e.ensemble_by = "weights";
  e.ensemble_from = 4000;
  e.ensemble_mean = 850.25;
  e.ensemble_std = 12.5;
  e.ensemble_min = 790;
  e.ensemble_max = 931.5;
  e.ensemble_returns = {790, 931.5, 829.25};
  for (const EvalRecord& r : {a, b, c, d, e}) AppendJsonLine(path, r);

  const std::string text = ReadFile(path);
  EXPECT_EQ(testing::CountOccurrences(text, "\n"), 5);
  EXPECT_EQ(
      testing::CountOccurrences(
          text, "\"ensemble_size\": 5, \"ensemble_by\": \"weights\", \"ensemble_from\": 4000"),
      1);
  EXPECT_EQ(testing::CountOccurrences(text, "\"ensemble_"), 8);
  EXPECT_EQ(testing::CountOccurrences(text, "\"second_mean\": 642.125"), 1);
  EXPECT_EQ(testing::CountOccurrences(text, "\"value_correlation\": null"), 1);
  EXPECT_EQ(testing::CountOccurrences(text, "\"returns\": [-0.1,912.5,"), 1);
  EXPECT_EQ(testing::CountOccurrences(text, "\"steps\": [1,200,0]"), 1);
  EXPECT_EQ(testing::CountOccurrences(text, "\"action_mean\": [0.25,-0.5,0.125]"), 1);
  int skipped = -1;
  const std::vector<EvalRecord> back = LoadJsonLines(path, &skipped);
  EXPECT_EQ(skipped, 0);
  ASSERT_EQ(back.size(), 5U);
  EXPECT_EQ(back[0], a);
  EXPECT_EQ(back[1], b);
  EXPECT_EQ(back[2], c);
  EXPECT_EQ(back[3], d);
  EXPECT_EQ(back[4], e);
}

TEST(JsonLinesTest, ALineHasTheDocumentedFields) {
  const std::string line = ToJson(Record("c.bin", 10, 9.5));
  for (const char* key : {"\"checkpoint\": \"c.bin\"", "\"update\": 10", "\"env_steps\": 40",
                          "\"wall_seconds\":", "\"mean\": 9.5",
                          "\"std\":", "\"min\":", "\"max\":", "\"episodes\": 100"}) {
    EXPECT_NE(line.find(key), std::string::npos) << key << " missing in " << line;
  }
  EXPECT_EQ(line.find('\n'), std::string::npos);
}

TEST(JsonLinesTest, ATornLastLineIsSkippedAndCounted) {
  TempDir dir;
  const std::string path = dir / "eval.jsonl";
  AppendJsonLine(path, Record("a.bin", 1, 10));
  AppendJsonLine(path, Record("b.bin", 2, 20));
  {
    std::ofstream out(path, std::ios::app);
    out << "{\"checkpoint\": \"c.bin\", \"upd";
  }
  int skipped = 0;
  const std::vector<EvalRecord> back = LoadJsonLines(path, &skipped);
  EXPECT_EQ(skipped, 1);
  ASSERT_EQ(back.size(), 2U);
  EXPECT_EQ(back[1].checkpoint, "b.bin");
}

TEST(JsonLinesTest, AMissingFileGivesNoRecords) {
  TempDir dir;
  int skipped = -1;
  EXPECT_TRUE(LoadJsonLines(dir / "nothing.jsonl", &skipped).empty());
  EXPECT_EQ(skipped, 0);
}

TEST(JsonLinesTest, ParseAcceptsOtherKeyOrderAndRejectsNonObjects) {
  EvalRecord r;
  ASSERT_TRUE(ParseJson(R"({ "mean" : 12.5, "extra": "y", "update": 3, "checkpoint": "x" })", &r));
  EXPECT_EQ(r.checkpoint, "x");
  EXPECT_EQ(r.update, 3);
  EXPECT_EQ(r.mean, 12.5);
  EXPECT_TRUE(r.returns.empty());
  // Returns that are not an array of numbers are read as none; the record stands.
  ASSERT_TRUE(ParseJson(R"({"checkpoint": "x", "update": 3, "mean": 1, "returns": [1, "a"]})", &r));
  EXPECT_TRUE(r.returns.empty());
  ASSERT_TRUE(
      ParseJson(R"({"checkpoint": "x", "update": 3, "mean": 1, "returns": [1, null]})", &r));
  ASSERT_EQ(r.returns.size(), 2U);
  EXPECT_EQ(r.returns[0], 1);
  EXPECT_TRUE(std::isnan(r.returns[1]));
  // Steps must be whole numbers from 0.
  for (const char* steps : {"[1, 2.5]", "[-1]", "[1, null]", "[\"1\"]"}) {
    ASSERT_TRUE(ParseJson(
        std::string(R"({"checkpoint": "x", "update": 3, "mean": 1, "steps": )") + steps + "}", &r));
    EXPECT_TRUE(r.steps.empty()) << steps;
  }
  ASSERT_TRUE(ParseJson(R"({"checkpoint": "x", "update": 3, "mean": 1, "steps": [7, 0]})", &r));
  EXPECT_EQ(r.steps, (std::vector<int>{7, 0}));
  // An ensemble size without its mean is no ensemble.
  ASSERT_TRUE(ParseJson(R"({"checkpoint": "x", "update": 3, "mean": 1, "ensemble_size": 5})", &r));
  EXPECT_EQ(r.ensemble_size, 0);
  // Lines from before averages of weights were scored hold ensembles of actions.
  ASSERT_TRUE(ParseJson(
      R"({"checkpoint": "x", "update": 3, "mean": 1, "ensemble_size": 5, "ensemble_mean": 2})",
      &r));
  EXPECT_EQ(r.ensemble_size, 5);
  EXPECT_EQ(r.ensemble_by, "actions");
  EXPECT_FALSE(ParseJson("[1, 2]", &r));
  EXPECT_FALSE(ParseJson(R"({"checkpoint": "x", "update": 3})", &r));  // no mean
  EXPECT_FALSE(ParseJson(R"({"checkpoint": "x", "update": 3, "mean": 1} trailing)", &r));
  EXPECT_FALSE(ParseJson("", &r));
}

TEST(JsonLinesTest, AppendingToAnUnwritablePathThrowsNamingIt) {
  TempDir dir;
  const std::string path = dir / "no/such/dir/eval.jsonl";
  try {
    AppendJsonLine(path, Record("a.bin", 1, 1));
    FAIL() << "expected an exception";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
  }
}

TEST(EvalHistoryTest, KeepsAddedRecordsAndReloadsThemWithTheSkippedLines) {
  TempDir dir;
  const std::string path = dir / "eval.jsonl";
  {
    EvalHistory history(path);
    EXPECT_TRUE(history.records().empty());
    EXPECT_EQ(history.best(), nullptr);
    history.Add(Record("a.bin", 1, 10));
    history.Add(Record("b.bin", 2, 30));
    history.Add(Record("c.bin", 3, 30));
    ASSERT_NE(history.best(), nullptr);
    EXPECT_EQ(history.best()->checkpoint, "b.bin");  // the first with the highest mean
    EXPECT_TRUE(history.Contains("b.bin", 2));
    EXPECT_FALSE(history.Contains("b.bin", 3));
  }
  std::ofstream(path, std::ios::app) << "{\"checkpoint\": \"d.bin\", \"upd";
  const EvalHistory again(path);
  EXPECT_EQ(again.records().size(), 3U);
  EXPECT_EQ(again.skipped_lines(), 1);
  EXPECT_EQ(again.path(), path);
  EXPECT_TRUE(again.Contains("c.bin", 3));
}

TEST(EvalHistoryTest, WithoutAFileKeepsRecordsInMemoryOnly) {
  EvalHistory history;
  history.Add(Record("a.bin", 1, 10));
  EXPECT_EQ(history.records().size(), 1U);
  EXPECT_TRUE(history.path().empty());
}

TEST(EvalHistoryTest, AnUnwritableFileKeepsTheRecordAndThrows) {
  TempDir dir;
  EvalHistory history(dir / "no/such/dir/eval.jsonl");
  EXPECT_THROW(history.Add(Record("a.bin", 1, 10)), std::runtime_error);
  EXPECT_EQ(history.records().size(), 1U);
}

}  // namespace
}  // namespace rl::evaluator
