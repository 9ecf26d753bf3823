#include "tools/compare_runs.h"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "evaluator/report.h"
#include "tests/common/error_of.h"
#include "tests/common/read_file.h"
#include "tests/common/temp_dir.h"

namespace rl::tools {
namespace {

namespace fs = std::filesystem;
using evaluator::EvalRecord;

// A scratch folder with run folders as scripts/launch.sh leaves them (config.ini, eval.jsonl).
class CompareRunsTest : public TempDirTest {
 protected:
  // Writes dir_/name/config.ini (launch.sh's header lines and a preset body).
  std::string MakeRun(const std::string& name, const std::string& preset, const std::string& env,
                      int seed, double goal) {
    const fs::path dir = dir_ / name;
    fs::create_directories(dir);
    std::ofstream config(dir / "config.ini");
    config << "# Run of preset '" << preset << "', started 2026-11-22T10:15:00+00:00\n"
           << "# run-id = 12345\n"
           << "# lcm-url = udpm://239.255.76.67:7667?ttl=0\n"
           << "# actors = 4 (of 4), seed = " << seed << ", goal = " << goal
           << ", time budget = 600 s\n\n"
           << "# A preset comment with env = Wrong-v0 in it.\nenv = " << env
           << "\ngamma = 0.99\n\n[actor]\nenv = AlsoWrong-v0\n";
    return dir.string();
  }

  // One evaluation of a run: a checkpoint's update, env steps and wall seconds, and the mean
  // score of its episodes with their standard deviation.
  struct Eval {
    int64_t update;
    int64_t steps;
    double wall;
    double mean;
    double std = 10;
    double ensemble = std::nan("");  // the mean of its ensemble of 5; NaN: none scored
    bool averaged = false;           // the ensemble is an average of weights
  };

  // Appends `evals` to dir/eval.jsonl as the evaluator writes them (100 episodes each, min and
  // max one standard deviation from the mean).
  static void AddEvals(const std::string& dir, std::initializer_list<Eval> evals) {
    for (const Eval& e : evals) {
      EvalRecord r;
      r.checkpoint = "ckpt-" + std::to_string(e.update) + ".bin";
      r.update = e.update;
      r.env_steps = e.steps;
      r.wall_seconds = e.wall;
      r.mean = e.mean;
      r.std = e.std;
      r.min = e.mean - e.std;
      r.max = e.mean + e.std;
      r.episodes = 100;
      if (std::isfinite(e.ensemble)) {
        r.ensemble_size = 5;
        r.ensemble_by = e.averaged ? "weights" : "actions";
        r.ensemble_from = e.update - 200;
        r.ensemble_mean = e.ensemble;
        r.ensemble_std = e.std;
      }
      evaluator::AppendJsonLine(dir + "/eval.jsonl", r);
    }
  }

  static int Count(const std::string& text, const std::string& what) {
    int n = 0;
    for (size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
    return n;
  }

  // The texts of the cells of the table row that holds `marker` (the first after `from`): tags
  // become spaces, runs of spaces one.
  static std::vector<std::string> RowCells(const std::string& html, size_t from,
                                           const std::string& marker) {
    const size_t at = html.find(marker, from);
    if (at == std::string::npos) return {"(no row with " + marker + ")"};
    const size_t begin = html.rfind("<tr", at + marker.size() - 1);
    const std::string row = html.substr(begin, html.find("</tr>", at) - begin);
    std::vector<std::string> cells;
    for (size_t td = row.find("<td"); td != std::string::npos; td = row.find("<td", td + 1)) {
      const size_t content = row.find('>', td) + 1;
      const std::string cell = row.substr(content, row.find("</td>", content) - content);
      std::string text;
      bool in_tag = false;
      for (char c : cell) {
        if (c == '<' || c == '>') {
          in_tag = c == '<';
          c = ' ';
        } else if (in_tag) {
          continue;
        }
        if (c == ' ' && (text.empty() || text.back() == ' ')) continue;
        text += c;
      }
      while (!text.empty() && text.back() == ' ') text.pop_back();
      cells.push_back(text);
    }
    return cells;
  }
};

TEST_F(CompareRunsTest, LoadsThePresetEnvGoalSeedAndEvaluations) {
  const std::string dir = MakeRun("cartpole-1", "cartpole", "CartPole-v1", 3, 475);
  AddEvals(dir, {{500, 10000, 4.5, 120}, {1000, 20000, 9.0, 480.5}});
  const CompareRun run = LoadCompareRun(dir);
  EXPECT_EQ(run.preset, "cartpole");
  EXPECT_EQ(run.env_id, "CartPole-v1");
  EXPECT_EQ(run.goal, 475);
  EXPECT_EQ(run.seed, 3);
  EXPECT_EQ(run.label, "cartpole-1");
  ASSERT_EQ(run.records.size(), 2u);
  EXPECT_EQ(run.records[1].mean, 480.5);
}

TEST_F(CompareRunsTest, RefusesFoldersThatAreNotScoredRuns) {
  // The message of the error LoadCompareRun throws, which must be a std::runtime_error.
  const auto message = [](const std::string& dir) {
    EXPECT_THROW(LoadCompareRun(dir), std::runtime_error) << dir;
    return ErrorOf([&] { LoadCompareRun(dir); });
  };
  EXPECT_NE(message((dir_ / "missing").string()).find("not a folder"), std::string::npos);
  fs::create_directories(dir_ / "bare");
  EXPECT_NE(message((dir_ / "bare").string()).find("no config.ini"), std::string::npos);
  const std::string unscored = MakeRun("unscored", "cartpole", "CartPole-v1", 1, 475);
  EXPECT_NE(message(unscored).find("no eval.jsonl"), std::string::npos);
  std::ofstream(unscored + "/eval.jsonl") << "{\"checkpoint\": \"ckpt-1.bin\", \"upd";
  const std::string torn = message(unscored);
  EXPECT_NE(torn.find("no evaluation"), std::string::npos) << torn;
  EXPECT_EQ(torn.find('\n'), std::string::npos) << "one line: " << torn;
  fs::create_directories(dir_ / "foreign");
  std::ofstream(dir_ / "foreign" / "config.ini") << "env = CartPole-v1\n";
  std::ofstream(dir_ / "foreign" / "eval.jsonl") << "\n";
  EXPECT_NE(message((dir_ / "foreign").string()).find("no \"# Run of preset\" line"),
            std::string::npos);
}

TEST_F(CompareRunsTest, BestSoFarStepsAtEveryImprovementAndEndsAtTheLastEvaluation) {
  const std::string dir = MakeRun("r", "cartpole", "CartPole-v1", 1, 475);
  AddEvals(dir, {{4, 400, 4, 15}, {1, 100, 1, 10}, {2, 200, 2, 5}, {3, 300, 3, 20}});
  const CompareRun run = LoadCompareRun(dir);
  const std::vector<StepPoint> steps = BestSoFar(run, CurveAxis::kEnvSteps);
  ASSERT_EQ(steps.size(), 3u);
  EXPECT_EQ(steps[0].x, 100);
  EXPECT_EQ(steps[0].y, 10);
  EXPECT_EQ(steps[1].x, 300);
  EXPECT_EQ(steps[1].y, 20);
  EXPECT_EQ(steps[2].x, 400);
  EXPECT_EQ(steps[2].y, 20);
  const std::vector<StepPoint> by_time = BestSoFar(run, CurveAxis::kWallSeconds);
  ASSERT_EQ(by_time.size(), 3u);
  EXPECT_EQ(by_time[1].x, 3);
}

TEST_F(CompareRunsTest, CombinesStepsFromWhereEveryRunHasAValueAndHoldsTheirLastValue) {
  const std::vector<StepPoint> a = {{100, 10}, {300, 20}, {400, 20}};
  const std::vector<StepPoint> b = {{200, 0}, {250, 30}};
  const std::vector<GroupPoint> g = CombineSteps({a, b});
  ASSERT_EQ(g.size(), 4u);
  const double want[][4] = {
      {200, 5, 0, 10}, {250, 20, 10, 30}, {300, 25, 20, 30}, {400, 25, 20, 30}};
  for (size_t i = 0; i < g.size(); ++i) {
    EXPECT_EQ(g[i].x, want[i][0]) << i;
    EXPECT_EQ(g[i].mean, want[i][1]) << i;
    EXPECT_EQ(g[i].min, want[i][2]) << i;
    EXPECT_EQ(g[i].max, want[i][3]) << i;
  }
  EXPECT_TRUE(CombineSteps({a, {}}).empty());
  EXPECT_TRUE(CombineSteps({}).empty());
}

TEST_F(CompareRunsTest, SummarizesBestFinalAndTheFirstEvaluationAtTheGoal) {
  const std::string dir = MakeRun("r", "cartpole", "CartPole-v1", 1, 475);
  AddEvals(dir, {{500, 10000, 5, 300},
                 {1000, 20000, 10, 476},
                 {1500, 30000, 15, 490},
                 {2000, 40000, 20, 490},
                 {2500, 50000, 25, 410}});
  const RunSummary s = Summarize(LoadCompareRun(dir));
  EXPECT_EQ(s.evaluations, 5);
  EXPECT_EQ(s.best.update, 1500);
  EXPECT_EQ(s.final.update, 2500);
  EXPECT_TRUE(s.goal_reached);
  EXPECT_EQ(s.first_goal.update, 1000);
}

TEST_F(CompareRunsTest, ShowsEachRunsBestEnsembleOnlyWhenSomeRunHasOne) {
  const std::string one = MakeRun("one", "car", "CarRacing-v3", 1, 900);
  AddEvals(one, {{500, 1000, 10, 700, 10, 720.5}, {1000, 2000, 20, 800, 10, 710}});
  const std::string two = MakeRun("two", "car", "CarRacing-v3", 2, 900);
  AddEvals(two, {{500, 1000, 10, 650}});
  std::vector<CompareRun> runs = {LoadCompareRun(two)};
  MakeLabelsUnique(&runs);
  EXPECT_EQ(Summarize(runs[0]).best_ensemble.ensemble_size, 0);
  EXPECT_EQ(RenderComparePage(runs, "").find("best ensemble"), std::string::npos);

  runs.insert(runs.begin(), LoadCompareRun(one));
  MakeLabelsUnique(&runs);
  const RunSummary s = Summarize(runs[0]);
  EXPECT_EQ(s.best.update, 1000);
  EXPECT_EQ(s.best_ensemble.update, 500);  // the best ensemble is not the best checkpoint's
  const std::string html = RenderComparePage(runs, "");
  const size_t runs_table = html.find("<h2>Runs</h2>");
  ASSERT_NE(runs_table, std::string::npos);
  EXPECT_NE(html.find("<th>best ensemble</th>", runs_table), std::string::npos);
  EXPECT_EQ(RowCells(html, runs_table, ">one<").back(),
            "720.5 \xC2\xB1 10.0 5, updates 300 to 500");
  EXPECT_EQ(RowCells(html, runs_table, ">two<").back(), "\xE2\x80\x94");
  // An average of weights says so.
  const std::string three = MakeRun("three", "car", "CarRacing-v3", 3, 900);
  AddEvals(three, {{500, 1000, 10, 700, 10, 730.5, true}});
  runs.push_back(LoadCompareRun(three));
  MakeLabelsUnique(&runs);
  const std::string with_average = RenderComparePage(runs, "");
  EXPECT_EQ(RowCells(with_average, with_average.find("<h2>Runs</h2>"), ">three<").back(),
            "730.5 \xC2\xB1 10.0 5 averaged, updates 300 to 500");
}

TEST_F(CompareRunsTest, ARunWithMetricsSaysItsTrainingEpisodesAtItsBest) {
  const std::string dir = MakeRun("kuka-1", "kuka_grasp", "KukaDiverseObjectGrasping-v0", 1, 0.6);
  AddEvals(dir, {{100, 700, 60, 0.4, 0.05}, {200, 1400, 120, 0.55, 0.05}});
  std::vector<CompareRun> runs = {LoadCompareRun(dir)};
  EXPECT_TRUE(runs[0].episodes.empty()) << "no metrics.jsonl";
  const std::string plain = RenderComparePage(runs, "");
  EXPECT_EQ(RowCells(plain, plain.find("<h2>Runs</h2>"), ">kuka-1<")[4], "1,400");

  std::ofstream(dir + "/metrics.jsonl")
      << "{\"t\": 50, \"role\": \"actor-0\", \"episodes\": 90}\n"
      << "{\"t\": 50, \"role\": \"learner\", \"updates\": 110}\n"
      << "{\"t\": 110, \"role\": \"actor-0\", \"episodes\": 180}\n"
      << "{\"t\": 110, \"role\": \"learner\", \"updates\": 205}\n";
  runs = {LoadCompareRun(dir)};
  EXPECT_EQ(runs[0].episodes.size(), 2u);
  const std::string html = RenderComparePage(runs, "");
  EXPECT_EQ(RowCells(html, html.find("<h2>Runs</h2>"), ">kuka-1<")[4], "1,400 180 episodes");
}

TEST_F(CompareRunsTest, LabelsRunsOfTheSameNameByTheirParentFolders) {
  std::vector<CompareRun> runs(3);
  fs::create_directories(dir_ / "x" / "run");
  fs::create_directories(dir_ / "y" / "run");
  fs::create_directories(dir_ / "z");
  runs[0].dir = (dir_ / "x" / "run").string();
  runs[1].dir = (dir_ / "y" / "run").string() + "/";
  runs[2].dir = (dir_ / "z").string();
  MakeLabelsUnique(&runs);
  EXPECT_EQ(runs[0].label, "x/run");
  EXPECT_EQ(runs[1].label, "y/run");
  EXPECT_EQ(runs[2].label, "z");
}

TEST_F(CompareRunsTest, PageOfTwoRunsShowsBothRunsTheirGroupAndTheirSummaryNumbers) {
  const std::string one = MakeRun("cartpole-seed1", "cartpole", "CartPole-v1", 1, 475);
  AddEvals(one,
           {{500, 12000, 6.5, 150.25}, {1000, 24690, 42.2, 480.5, 12}, {1500, 37035, 63, 470}});
  const std::string two = MakeRun("cartpole-seed2", "cartpole", "CartPole-v1", 2, 475);
  AddEvals(two, {{500, 11000, 5.1, 311.9, 20}, {1000, 22000, 150, 200}});
  fs::create_directories(one + "/report");
  std::ofstream(one + "/report/index.html") << "<!DOCTYPE html>\n";
  std::vector<CompareRun> runs = {LoadCompareRun(one), LoadCompareRun(two)};
  MakeLabelsUnique(&runs);
  const fs::path page = dir_ / "compare.html";
  WriteComparePage(page.string(), runs);
  const std::string html = ReadFile(page);
  ASSERT_FALSE(html.empty());

  // Self-contained: inline SVG, nothing fetched, no script.
  EXPECT_EQ(Count(html, "<svg "), 2) << "one env: a plot against env steps, one against time";
  EXPECT_EQ(html.find("<script"), std::string::npos);
  EXPECT_EQ(html.find("http://"), html.find("http://www.w3.org/2000/svg"));
  EXPECT_EQ(html.find("https://"), std::string::npos);
  EXPECT_EQ(html.find("<img"), std::string::npos);
  // Both runs, thin, in both plots; the group's mean and band once per plot.
  EXPECT_EQ(Count(html, "<path class=\"run\""), 4);
  EXPECT_EQ(Count(html, "<path class=\"mean\""), 2);
  EXPECT_EQ(Count(html, "<path class=\"band\""), 2);
  EXPECT_EQ(Count(html, "<line class=\"goal\""), 2);
  EXPECT_NE(html.find("best evaluation mean so far"), std::string::npos);
  EXPECT_NE(html.find("CartPole-v1"), std::string::npos);

  // The run table: names (the first links to its report), seed, evaluations, best with its std,
  // where and when, final, the last evaluation, the goal.
  EXPECT_NE(html.find("<a href=\"cartpole-seed1/report/index.html\""), std::string::npos);
  const size_t runs_table = html.find("<h2>Runs</h2>");
  ASSERT_NE(runs_table, std::string::npos);
  EXPECT_EQ(RowCells(html, runs_table, ">cartpole-seed1<"),
            (std::vector<std::string>{"cartpole-seed1", "1", "3", "480.5 \xC2\xB1 12.0", "24,690",
                                      "42 s", "470.0 \xC2\xB1 10.0", "37,035 steps 1 min 03 s",
                                      "24,690 steps 42 s"}));
  EXPECT_EQ(RowCells(html, runs_table, ">cartpole-seed2<"),
            (std::vector<std::string>{"cartpole-seed2", "2", "2", "311.9 \xC2\xB1 20.0", "11,000",
                                      "5.1 s", "200.0 \xC2\xB1 10.0", "22,000 steps 2 min 30 s",
                                      "not reached (\xE2\x89\xA5 475)"}));
  // The group: 2 runs, 5 evaluations, 1 of 2 at the goal; means over the runs with their range.
  EXPECT_EQ(RowCells(html, 0, "<tr class=\"group\">"),
            (std::vector<std::string>{"cartpole", "2", "5", "1 of 2 mean \xE2\x89\xA5 475",
                                      "396.2 311.9 to 480.5", "17,845 11,000 to 24,690",
                                      "24 s 5.1 s to 42 s", "335.0 200.0 to 470.0",
                                      "24,690 steps, 42 s the 1 that reached it"}));
}

TEST_F(CompareRunsTest, RunsOfTwoPresetsFormTwoGroupsAndTwoEnvsGetTheirOwnPlots) {
  const std::string a = MakeRun("a", "cartpole", "CartPole-v1", 1, 475);
  AddEvals(a, {{1, 100, 1, 100}});
  const std::string b = MakeRun("b", "pendulum", "Pendulum-v1", 1, -200);
  AddEvals(b, {{1, 100, 1, -1200}, {2, 200, 2, -180}});
  const std::string c = MakeRun("c", "cartpole_big", "CartPole-v1", 1, 475);
  AddEvals(c, {{1, 100, 1, 90}});
  std::vector<CompareRun> runs = {LoadCompareRun(a), LoadCompareRun(b), LoadCompareRun(c)};
  MakeLabelsUnique(&runs);
  const std::string html = RenderComparePage(runs, "");
  EXPECT_EQ(Count(html, "<svg "), 4) << "CartPole-v1 and Pendulum-v1, two plots each";
  EXPECT_EQ(Count(html, "<tr class=\"group\">"), 3);
  EXPECT_EQ(Count(html, "<path class=\"mean\""), 0) << "no group has several runs";
  EXPECT_EQ(html.find("<a href="), std::string::npos) << "no page folder: no links";
  // The CartPole plots come first and hold the two cartpole presets, not the pendulum run.
  const size_t pendulum_plot = html.find("Pendulum-v1</span></h2>");
  ASSERT_NE(pendulum_plot, std::string::npos);
  EXPECT_LT(html.find("CartPole-v1</span></h2>"), pendulum_plot);
  EXPECT_EQ(Count(html.substr(0, pendulum_plot), "<path class=\"run\""), 4);
  EXPECT_NE(html.find("goal -200"), std::string::npos);
}

}  // namespace
}  // namespace rl::tools
