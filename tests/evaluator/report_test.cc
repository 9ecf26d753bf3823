#include "evaluator/report.h"

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "file_helpers.h"
#include "sample_record.h"
#include "tests/common/read_file.h"
#include "tests/common/temp_dir.h"

namespace rl::evaluator {
namespace {

using testing::CountOccurrences;

// A record with plausible numbers.
constexpr auto& Record = testing::SampleRecord;

ReportInfo Info(double goal) {
  ReportInfo info;
  info.env_id = "CartPole-v1";
  info.run_name = "cartpole-dqn";
  info.run_id = 4242;
  info.goal = goal;
  info.run_config = "env = CartPole-v1\n[learner]\nlr = 0.0005\n";
  return info;
}

// Writes the report of `records` into `folder` (WriteReport) and returns its index.html.
std::string WriteAndRead(const std::string& folder, const std::vector<EvalRecord>& records,
                         const ReportInfo& info) {
  WriteReport(folder, records, info);
  return ReadFile(folder + "/index.html");
}

// Each test writes its reports into a folder of its own.
class ReportTest : public ::testing::Test {
 protected:
  TempDir dir_;
};

TEST_F(ReportTest, WritesIndexWithOneRowPerCheckpointNewestFirstAndBothCurves) {
  const std::string report = dir_ / "report";
  const std::vector<EvalRecord> records = {Record("ckpt_a.bin", 1000, 20.0),
                                           Record("ckpt_b.bin", 2000, 180.0),
                                           Record("ckpt_c.bin", 3000, 90.0)};
  const std::string html = WriteAndRead(report, records, Info(475));
  ASSERT_FALSE(html.empty());
  EXPECT_NE(html.find("<title>"), std::string::npos);
  EXPECT_NE(html.find("CartPole-v1"), std::string::npos);
  EXPECT_NE(html.find("cartpole-dqn"), std::string::npos);
  const size_t tbody = html.find("<tbody>");
  ASSERT_NE(tbody, std::string::npos);
  const std::string rows = html.substr(tbody, html.find("</tbody>") - tbody);
  EXPECT_EQ(CountOccurrences(rows, "<tr"), 3);
  // Newest (highest update) first.
  const size_t c = rows.find("ckpt_c.bin"), b = rows.find("ckpt_b.bin"),
               a = rows.find("ckpt_a.bin");
  ASSERT_NE(a, std::string::npos);
  EXPECT_LT(c, b);
  EXPECT_LT(b, a);
  // The best checkpoint is marked and summarized; the goal was not reached.
  EXPECT_NE(rows.find("<tr class=\"best\"><td>ckpt_b.bin"), std::string::npos);
  EXPECT_NE(html.find("180.0"), std::string::npos);
  EXPECT_NE(html.find("not reached"), std::string::npos);
  // Both curves are referenced and exist, with a line, a band and a dashed goal.
  for (const char* svg : {"curve_env_steps.svg", "curve_wall_time.svg"}) {
    EXPECT_NE(html.find(std::string("<img src=\"") + svg + "\""), std::string::npos) << svg;
    const std::string text = ReadFile(report + "/" + svg);
    EXPECT_EQ(text.rfind("<svg", 0), 0U) << svg;
    EXPECT_NE(text.find("<polyline class=\"mean\""), std::string::npos) << svg;
    EXPECT_NE(text.find("<path class=\"band\""), std::string::npos) << svg;
    EXPECT_NE(text.find("stroke-dasharray"), std::string::npos) << svg;
    EXPECT_NE(text.find("goal 475"), std::string::npos) << svg;
  }
  // Self-contained: no scripts, nothing fetched from the network.
  EXPECT_EQ(html.find("<script"), std::string::npos);
  EXPECT_EQ(html.find("http://"), std::string::npos);
  EXPECT_EQ(html.find("https://"), std::string::npos);
  // No temporary file is left behind.
  for (const auto& entry : std::filesystem::directory_iterator(report)) {
    EXPECT_NE(entry.path().extension(), ".tmp") << entry.path();
  }
}

TEST_F(ReportTest, ShowsValueEstimatesOnlyWhenMeasuredAndSmallScoresWithTwoDecimals) {
  const std::string report = dir_ / "report";
  std::string html = WriteAndRead(report, {Record("a.bin", 1000, 0.36)}, Info(0.6));
  EXPECT_NE(html.find(">0.36<"), std::string::npos);  // not rounded to 0.4
  EXPECT_EQ(html.find("<th>Q</th>"), std::string::npos);

  EvalRecord r = Record("b.bin", 2000, 0.46);
  r.value_steps = 700;
  r.value_estimate = 0.412;
  r.value_return = 0.305;
  r.value_correlation = 0.2349;
  html = WriteAndRead(report, {Record("a.bin", 1000, 0.36), r}, Info(0.6));
  EXPECT_NE(html.find("<th>Q</th><th>G</th><th>r</th>"), std::string::npos);
  EXPECT_NE(html.find("<td>0.41</td><td>0.30</td><td>0.23</td>"), std::string::npos);
  EXPECT_NE(html.find("van Hasselt"), std::string::npos);
}

TEST_F(ReportTest, ShowsTheTenthPercentileAndMedianOfTheReturnsOnlyWhenKept) {
  const std::string report = dir_ / "report";
  std::string html = WriteAndRead(report, {Record("a.bin", 1000, 450)}, Info(900));
  EXPECT_EQ(html.find("<th>median</th>"), std::string::npos);

  // An older line without returns beside one with them (the order of the episodes is not
  // sorted): 10 % at 90, interpolated between 0 and 100; the median at 450.
  EvalRecord r = Record("b.bin", 2000, 450);
  r.returns = {900, 0, 800, 100, 700, 200, 600, 300, 500, 400};
  html = WriteAndRead(report, {Record("a.bin", 1000, 450), r}, Info(900));
  EXPECT_NE(html.find("<th>min</th><th>10 %</th><th>median</th><th>max</th>"), std::string::npos);
  EXPECT_NE(html.find("<td>90.0</td><td>450.0</td><td>675</td>"), std::string::npos) << html;
  EXPECT_NE(html.find("<td>225</td><td></td><td></td><td>675</td>"), std::string::npos);
  EXPECT_NE(html.find("a few failed episodes"), std::string::npos);
}

TEST_F(ReportTest, ShowsTheMeanActionOnlyWhenKept) {
  const std::string report = dir_ / "report";
  std::string html = WriteAndRead(report, {Record("a.bin", 1000, 450)}, Info(900));
  EXPECT_EQ(html.find("<th>mean action</th>"), std::string::npos);
  EvalRecord r = Record("b.bin", 2000, 715);
  r.action_mean = {-0.051, 1.0, 0.1585};
  html = WriteAndRead(report, {Record("a.bin", 1000, 450), r}, Info(900));
  EXPECT_NE(html.find("<th>mean action</th>"), std::string::npos);
  EXPECT_NE(html.find("<td>-0.05, 1.00, 0.16</td>"), std::string::npos) << html;
  EXPECT_NE(html.find("steer, gas and brake"), std::string::npos);
}

TEST_F(ReportTest, ShowsTheBestEnsembleAndAnEnsembleColumnOnlyWhenScored) {
  std::vector<EvalRecord> records = {Record("a.bin", 1000, 20.0), Record("b.bin", 2000, 180.0),
                                     Record("c.bin", 3000, 90.0)};
  const std::string without = WriteAndRead(dir_ / "without", records, Info(475));
  EXPECT_EQ(without.find("Best ensemble"), std::string::npos);
  EXPECT_EQ(without.find("<th>ensemble</th>"), std::string::npos);
  for (auto [i, mean] : {std::pair{1, 250.5}, std::pair{2, 300.25}}) {
    records[i].ensemble_size = 5;
    records[i].ensemble_from = records[i].update - 400;
    records[i].ensemble_mean = mean;
    records[i].ensemble_std = 12;
  }
  const std::string html = WriteAndRead(dir_ / "with", records, Info(475));
  EXPECT_NE(html.find("Best ensemble</div><div class=\"value\">300.2"), std::string::npos);
  EXPECT_NE(html.find("the mean action of 5 checkpoints, updates 2,600 to 3,000"),
            std::string::npos);
  EXPECT_NE(html.find("<th>ensemble</th>"), std::string::npos);
  EXPECT_NE(html.find("<td>250.5 \xC2\xB1 12.0 (5)</td>"), std::string::npos);
  EXPECT_NE(ReadFile(dir_ / "with/curve_wall_time.svg").find("ensemble of 5"), std::string::npos);
}

TEST_F(ReportTest, SaysWhenAndWhereTheGoalWasFirstReached) {
  const std::vector<EvalRecord> records = {
      Record("a.bin", 1000, 100.0), Record("b.bin", 2000, 480.0), Record("c.bin", 3000, 500.0)};
  const std::string html = WriteAndRead(dir_.path(), records, Info(475));
  EXPECT_NE(html.find("badge yes\">reached"), std::string::npos);
  EXPECT_NE(html.find("first at update 2,000"), std::string::npos);
  EXPECT_EQ(html.find("not reached"), std::string::npos);
}

TEST_F(ReportTest, EscapesTheConfigAndCheckpointNames) {
  ReportInfo info = Info(475);
  info.run_config = "note = a<b & \"c\" </pre><script>alert(1)</script>";
  info.run_name = "<b>run</b>";
  const std::string html = WriteAndRead(dir_.path(), {Record("<img src=x>.bin", 5, 1.0)}, info);
  EXPECT_NE(html.find("note = a&lt;b &amp; &quot;c&quot; &lt;/pre&gt;&lt;script&gt;alert(1)"
                      "&lt;/script&gt;"),
            std::string::npos);
  EXPECT_EQ(html.find("<script"), std::string::npos);
  EXPECT_EQ(html.find("<b>run</b>"), std::string::npos);
  EXPECT_NE(html.find("&lt;img src=x&gt;.bin"), std::string::npos);
  EXPECT_EQ(HtmlEscape("'&'"), "&#39;&amp;&#39;");
}

TEST_F(ReportTest, ShowsTheTsneMapWithItsCaptionOnlyWhenGiven) {
  EXPECT_EQ(WriteAndRead(dir_.path(), {Record("a.bin", 1, 1.0)}, Info(475)).find("t-SNE"),
            std::string::npos);
  ReportInfo info = Info(475);
  info.tsne_file = kTsneMap;
  info.tsne_caption = "Colour: max_a Q(s, a) <of> the state.";
  const std::string html = WriteAndRead(dir_.path(), {Record("a.bin", 1, 1.0)}, info);
  EXPECT_NE(html.find("<h2>Last hidden layer (t-SNE)</h2>"), std::string::npos);
  EXPECT_NE(html.find("<img src=\"tsne.png\""), std::string::npos);
  EXPECT_NE(html.find("Colour: max_a Q(s, a) &lt;of&gt; the state."), std::string::npos);
}

TEST_F(ReportTest, ListsTheRestartsOfTheRunsProcesses) {
  ReportInfo info = Info(475);
  info.restarts_file = dir_ / "restarts";
  // No file yet: no section.
  EXPECT_EQ(WriteAndRead(dir_.path(), {Record("a.bin", 1, 1.0)}, info).find("Restarts"),
            std::string::npos);
  std::ofstream(info.restarts_file) << "2026-11-25T12:00:01+00:00 learner status 137 restart 1\n"
                                       "torn line\n"
                                       "2026-11-25T12:00:09+00:00 replay status 137 restart 1\n"
                                       "2026-11-25T12:01:00+00:00 learner status 134 restart 2\n";
  const std::string html = WriteAndRead(dir_.path(), {Record("a.bin", 1, 1.0)}, info);
  EXPECT_NE(html.find("<h2>Restarts</h2>"), std::string::npos);
  EXPECT_NE(html.find("3 process restarts (learner 2, replay 1)"), std::string::npos);
  EXPECT_NE(html.find("<td>learner</td><td>134</td><td>2</td>"), std::string::npos);
  // An actor whose Slurm node was lost: not restarted.
  std::ofstream(info.restarts_file, std::ios::app)
      << "2026-11-25T12:02:00+00:00 actor-3 status 0 lost 0\n";
  EXPECT_NE(WriteAndRead(dir_.path(), {Record("a.bin", 1, 1.0)}, info)
                .find("<td>actor-3</td><td>0</td><td>node lost</td>"),
            std::string::npos);
}

TEST_F(ReportTest, AnEmptyHistoryStillGivesAReportAndCurves) {
  const std::string html = WriteAndRead(dir_ / "report", {}, Info(475));
  EXPECT_NE(html.find("No checkpoint scored yet"), std::string::npos);
  EXPECT_TRUE(std::filesystem::exists(dir_ / "report/curve_env_steps.svg"));
  EXPECT_TRUE(std::filesystem::exists(dir_ / "report/curve_wall_time.svg"));
}

TEST_F(ReportTest, RewritingReplacesTheOldReport) {
  WriteReport(dir_.path(), {Record("first.bin", 1, 1.0)}, Info(475));
  const std::string html = WriteAndRead(dir_.path(), {Record("second.bin", 2, 2.0)}, Info(475));
  EXPECT_EQ(html.find("first.bin"), std::string::npos);
  EXPECT_NE(html.find("second.bin"), std::string::npos);
}

}  // namespace
}  // namespace rl::evaluator
