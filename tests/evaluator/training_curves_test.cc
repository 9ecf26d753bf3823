#include "evaluator/training_curves.h"

#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "evaluator/report.h"
#include "tests/common/read_file.h"
#include "tests/common/temp_dir.h"

namespace rl::evaluator {
namespace {

// Two rows of two actors, a learner and a replay, then a torn line.
void WriteMetrics(const std::string& path) {
  std::ofstream out(path);
  out << R"({"t": 1.000, "role": "actor-0", "env_steps": 10, "mean_return": 10, "exploration": 0.4, "steps_per_second": 100})"
      << "\n"
      << R"({"t": 1.000, "role": "actor-1", "env_steps": 12, "mean_return": 30, "exploration": 0.2, "steps_per_second": 300})"
      << "\n"
      << R"({"t": 1.000, "role": "learner", "updates": 5, "updates_per_second": 50, "loss": 2.5, "mean_q": null})"
      << "\n"
      << R"({"t": 2.000, "role": "actor-0", "env_steps": 20, "mean_return": 50, "exploration": 0.1, "steps_per_second": 200})"
      << "\n"
      << R"({"t": 2.000, "role": "replay", "size": 77})"
      << "\n"
      << R"({"t": 2.000, "role": "learner", "updates": 9, "updates_per_second": 40, "loss": 1.5, "mean_q": 3})"
      << "\n"
      << R"({"t": 3.000, "role": "learner", "upd)";
}

const TrainingSeries* Find(const std::vector<TrainingSeries>& all, const std::string& file) {
  for (const TrainingSeries& s : all) {
    if (s.file == file) return &s;
  }
  return nullptr;
}

TEST(TrainingCurvesTest, CombinesTheActorsAndKeepsTheLearnerAndReplaySeries) {
  TempDir dir;
  const std::string path = dir / "metrics.jsonl";
  WriteMetrics(path);
  const std::vector<TrainingSeries> all = LoadTrainingSeries(path);

  const TrainingSeries* ret = Find(all, "train_return.svg");
  ASSERT_NE(ret, nullptr);
  ASSERT_EQ(ret->points.size(), 2u);
  EXPECT_DOUBLE_EQ(ret->points[0].x, 1.0);
  EXPECT_DOUBLE_EQ(ret->points[0].mean, 20.0);  // the mean of 10 and 30
  EXPECT_DOUBLE_EQ(ret->points[1].mean, 50.0);
  const TrainingSeries* speed = Find(all, "train_env_steps.svg");
  ASSERT_NE(speed, nullptr);
  EXPECT_DOUBLE_EQ(speed->points[0].mean, 400.0);  // summed over the actors
  const TrainingSeries* exploration = Find(all, "train_exploration.svg");
  ASSERT_NE(exploration, nullptr);
  EXPECT_NEAR(exploration->points[0].mean, 0.3, 1e-12);
  const TrainingSeries* loss = Find(all, "train_loss.svg");
  ASSERT_NE(loss, nullptr);
  ASSERT_EQ(loss->points.size(), 2u);  // the torn line at t = 3 is skipped
  EXPECT_DOUBLE_EQ(loss->points[1].mean, 1.5);
  const TrainingSeries* q = Find(all, "train_mean_q.svg");
  ASSERT_NE(q, nullptr);
  EXPECT_EQ(q->points.size(), 1u);  // null at t = 1 is left out
  const TrainingSeries* size = Find(all, "train_replay_size.svg");
  ASSERT_NE(size, nullptr);
  EXPECT_DOUBLE_EQ(size->points[0].mean, 77.0);
  EXPECT_TRUE(LoadTrainingSeries(dir / "missing.jsonl").empty());
}

TEST(TrainingCurvesTest, TheReportShowsATrainingSectionOnlyWithMetrics) {
  TempDir dir;
  ReportInfo info;
  info.env_id = "CartPole-v1";
  info.goal = 475;
  WriteReport(dir / "plain", {}, info);
  EXPECT_EQ(ReadFile(dir / "plain/index.html").find("<h2>Training</h2>"), std::string::npos);

  info.metrics_file = dir / "metrics.jsonl";
  WriteMetrics(info.metrics_file);
  WriteReport(dir / "report", {}, info);
  const std::string html = ReadFile(dir / "report/index.html");
  EXPECT_NE(html.find("<h2>Training</h2>"), std::string::npos);
  EXPECT_NE(html.find("<img src=\"train_loss.svg\""), std::string::npos);
  const std::string svg = ReadFile(dir / "report/train_loss.svg");
  EXPECT_NE(svg.find("<svg"), std::string::npos);
  EXPECT_NE(svg.find("Learner loss"), std::string::npos);
}

TEST(TrainingCurvesTest, EpisodesByUpdateCountEveryLifeOfTheActors) {
  TempDir dir;
  const std::string path = dir / "metrics.jsonl";
  {
    std::ofstream out(path);
    out << R"({"t": 1, "role": "learner", "updates": 0})"
        << "\n"  // before any actor line
        << R"({"t": 2, "role": "actor-0", "episodes": 5})"
        << "\n"
        << R"({"t": 2, "role": "actor-1", "episodes": 3})"
        << "\n"
        << R"({"t": 2, "role": "learner", "updates": 100})"
        << "\n"
        << R"({"t": 3, "role": "actor-0", "episodes": 2})"
        << "\n"  // restarted after 5
        << R"({"t": 3, "role": "evaluator", "episodes": 100})"
        << "\n"  // not an actor's
        << "not json\n"
        << R"({"t": 3, "role": "learner", "updates": 250})"
        << "\n"
        << R"({"t": 4, "role": "learner", "upd)";  // cut short
  }
  const ActorEpisodes episodes = LoadActorEpisodes(path);
  EXPECT_EQ(episodes.total, 5 + 2 + 3);
  const std::vector<EpisodesAtUpdate>& points = episodes.by_update;
  ASSERT_EQ(points.size(), 2u);
  EXPECT_EQ(points[0].updates, 100);
  EXPECT_EQ(points[0].episodes, 5 + 3);
  EXPECT_EQ(points[1].updates, 250);
  EXPECT_EQ(points[1].episodes, 5 + 2 + 3);
  EXPECT_EQ(EpisodesAt(points, 0), 8);
  EXPECT_EQ(EpisodesAt(points, 100), 8);
  EXPECT_EQ(EpisodesAt(points, 101), 10);  // the first point at or past the update
  EXPECT_EQ(EpisodesAt(points, 251), std::nullopt);
  EXPECT_TRUE(LoadActorEpisodes(dir / "missing.jsonl").by_update.empty());
}

TEST(TrainingCurvesTest, TheReportSaysTheTrainingEpisodesOfEachCheckpoint) {
  TempDir dir;
  ReportInfo info;
  info.env_id = "KukaDiverseObjectGrasping-v0";
  info.goal = 0.25;  // the goal card names the early checkpoint, the best card the late one
  EvalRecord early;
  early.checkpoint = "ckpt-000000100.bin";
  early.update = 100;
  early.mean = 0.3;
  EvalRecord late = early;
  late.checkpoint = "ckpt-000000300.bin";
  late.update = 300;  // past the metrics' last point
  late.mean = 0.7;
  WriteReport(dir / "plain", {early, late}, info);
  const std::string plain = ReadFile(dir / "plain/index.html");
  EXPECT_EQ(plain.find("training episodes"), std::string::npos) << "no metrics, no column";

  info.metrics_file = dir / "metrics.jsonl";
  {
    std::ofstream out(info.metrics_file);
    out << R"({"t": 1, "role": "actor-0", "episodes": 1234})"
        << "\n"
        << R"({"t": 1, "role": "learner", "updates": 150})"
        << "\n";
  }
  WriteReport(dir / "report", {early, late}, info);
  const std::string html = ReadFile(dir / "report/index.html");
  EXPECT_NE(html.find("<th>training episodes</th>"), std::string::npos);
  EXPECT_NE(html.find("<td>1,234</td>"), std::string::npos) << "the early checkpoint's";
  EXPECT_NE(html.find("update 100, 0 env steps, 1,234 training episodes"), std::string::npos)
      << "the goal card";
  EXPECT_NE(html.find("update 300, 0 env steps, 0.0 s"), std::string::npos)
      << "the best card, past the metrics: no episodes said";
}

}  // namespace
}  // namespace rl::evaluator
