#include "evaluator/evaluator_service.h"

#include <sys/stat.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "common/channels.h"
#include "common/lcm_bus.h"
#include "constant_lander.h"
#include "file_helpers.h"
#include "nn/checkpoint.h"
#include "nn/linear.h"
#include "nn/sequential.h"
#include "tests/common/read_file.h"
#include "tests/common/temp_dir.h"

namespace rl::evaluator {
namespace {

using testing::ConstantLanderCheckpoint;
using testing::CountOccurrences;
using testing::FifoUnblocker;
using testing::kLander;

BusConfig MemqConfig() { return InProcessBusConfig(77, "evaluator"); }

// A CartPole network that always pushes left (its output is the last layer's bias).
nn::Checkpoint AlwaysLeftCheckpoint(int64_t update) {
  std::mt19937 rng(3);
  nn::Sequential net = nn::MakeMlp(4, {16}, 2, &rng);
  nn::Checkpoint ckpt;
  ckpt.architecture = net.Architecture();
  ckpt.params.assign(static_cast<size_t>(net.NumParams()), 0.0f);
  ckpt.params[ckpt.params.size() - 2] = 1.0f;
  ckpt.meta.update = update;
  ckpt.meta.env_steps = update * 4;
  ckpt.meta.wall_seconds = static_cast<double>(update) / 100.0;
  ckpt.meta.run_id = 77;
  return ckpt;
}

// Checks that `r` (a published result or an EvalRecord) carries the metadata that
// AlwaysLeftCheckpoint(update) and Announce(path, update) give: `update`, 4 env steps an update and
// update / 100 seconds.
template <class Result>
void ExpectMetadataOfUpdate(const Result& r, int64_t update) {
  EXPECT_EQ(r.update, update);
  EXPECT_EQ(r.env_steps, update * 4);
  EXPECT_DOUBLE_EQ(r.wall_seconds, static_cast<double>(update) / 100.0);
}

// A CartPole network that balances the pole: its Q(right) - Q(left) is the state feedback
// u = x + x_dot + 10 theta + theta_dot (through relu(u) - relu(-u)), so it pushes towards the
// side the pole falls to and lasts far longer than AlwaysLeftCheckpoint.
nn::Checkpoint BalancingCheckpoint(int64_t update) {
  nn::Checkpoint ckpt = AlwaysLeftCheckpoint(update);
  std::mt19937 rng(3);
  nn::Sequential net = nn::MakeMlp(4, {16}, 2, &rng);
  std::vector<float> zero(static_cast<size_t>(net.NumParams()), 0.0f);
  net.SetFlat(zero.data(), zero.size());
  auto& hidden = dynamic_cast<nn::Linear&>(net.layer(0));
  auto& out = dynamic_cast<nn::Linear&>(net.layer(net.num_layers() - 1));
  const float gains[4] = {1, 1, 10, 1};
  for (int j = 0; j < 4; ++j) {
    hidden.weight()(0, j) = gains[j];
    hidden.weight()(1, j) = -gains[j];
  }
  out.weight()(1, 0) = 1;
  out.weight()(1, 1) = -1;
  net.GetFlat(&ckpt.params);
  return ckpt;
}

// A checkpoint of a random MLP (a hidden layer of 8) for Catch-v0 in stacks of two 10 x 5 frames.
nn::Checkpoint CatchCheckpoint(int64_t update) {
  std::mt19937 rng(5);
  nn::Sequential net = nn::MakeMlp(2 * 10 * 5, {8}, 3, &rng);
  nn::Checkpoint ckpt;
  ckpt.architecture = net.Architecture();
  net.GetFlat(&ckpt.params);
  ckpt.meta.update = update;
  ckpt.meta.run_id = 77;
  return ckpt;
}

// Reads what was written to `f` from its start, and closes it.
std::string ReadAndClose(std::FILE* f) {
  std::rewind(f);
  std::string text;
  for (int ch; (ch = std::fgetc(f)) != EOF;) text += static_cast<char>(ch);
  std::fclose(f);
  return text;
}

// Whether `text` contains `part`; the failure shows the whole text.
::testing::AssertionResult Contains(const std::string& text, const std::string& part) {
  if (text.find(part) != std::string::npos) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << "no \"" << part << "\" in:\n" << text;
}

class EvaluatorServiceTest : public ::testing::Test {
 protected:
  EvaluatorServiceTest() : bus_(MemqConfig()) {
    std::filesystem::create_directories(checkpoints_);
    bus_.Subscribe<rlmsg::eval_result_t>(
        channels::kEval, [this](const rlmsg::eval_result_t& m) { results_.push_back(m); });
    bus_.Subscribe<rlmsg::stats_evaluator_t>(
        channels::kStatsEvaluator,
        [this](const rlmsg::stats_evaluator_t& m) { stats_.push_back(m); });
  }

  EvaluatorConfig Config() const {
    EvaluatorConfig c;
    c.episodes = 5;
    c.out_dir = (dir_ / "run-a").string();
    c.run_config_text = "env = CartPole-v1\n";
    return c;
  }
  // `c` with a video of each new best checkpoint, of `width` x `height` pixels.
  static EvaluatorConfig WithVideos(EvaluatorConfig c, int width, int height) {
    c.videos = true;
    c.video_width = width;
    c.video_height = height;
    return c;
  }
  // Config() with a screen of 2 episodes before the full evaluation.
  EvaluatorConfig ScreenConfig() const {
    EvaluatorConfig c = Config();
    c.screen_episodes = 2;
    return c;
  }
  // Config() on Catch in stacks of two 10 x 5 frames (see CatchCheckpoint).
  EvaluatorConfig CatchConfig() const {
    EvaluatorConfig c = Config();
    c.env_id = "Catch-v0+pixels(width=5,height=10,stack=2)";
    return c;
  }

  // Config() on LunarLanderContinuous, 2 episodes, ensembles of 2 by `by` (actions or weights).
  EvaluatorConfig EnsembleConfig(const std::string& by) const {
    EvaluatorConfig c = Config();
    c.env_id = kLander;
    c.episodes = 2;
    c.ensemble = 2;
    c.ensemble_by = by;
    return c;
  }
  // Scores two checkpoints of run 77 that always act (0.6, -0.4) and (0.2, 0), at updates 10 and
  // 20: the second has an ensemble, of the mean action (0.4, -0.2) either way.
  void ScoreTwoConstantLanders(EvaluatorService* service) {
    ASSERT_TRUE(
        AnnounceUntilResults(service, Save(ConstantLanderCheckpoint(10, 0.6f, -0.4f, 77)), 10, 1));
    ASSERT_TRUE(
        AnnounceUntilResults(service, Save(ConstantLanderCheckpoint(20, 0.2f, 0.0f, 77)), 20, 2));
  }

  // Saves `ckpt` in the run's checkpoint folder under the learner's name for it; returns its path.
  std::string Save(const nn::Checkpoint& ckpt) {
    std::string path = checkpoints_ + "/" + nn::CheckpointFileName(ckpt.meta.update);
    nn::SaveCheckpoint(path, ckpt);
    return path;
  }
  std::string WriteCheckpoint(int64_t update) { return Save(AlwaysLeftCheckpoint(update)); }

  void Announce(const std::string& path, int64_t update) {
    rlmsg::checkpoint_t m{};
    m.path = path;
    m.update = update;
    m.env_steps = update * 4;
    m.wall_seconds = static_cast<double>(update) / 100.0;
    ASSERT_TRUE(bus_.Publish(channels::kCheckpoint, &m));
  }

  // Polls until `done` holds (at most about two seconds). Returns whether it does.
  bool PollUntil(EvaluatorService* service, const std::function<bool()>& done) {
    for (int i = 0; i < 200 && !done(); ++i) service->Poll(10);
    return done();
  }
  // Announces the checkpoint at `path` and polls until `count` results have been published
  // (PollUntil).
  bool AnnounceUntilResults(EvaluatorService* service, const std::string& path, int64_t update,
                            size_t count) {
    Announce(path, update);
    return PollUntil(service, [&] { return results_.size() == count; });
  }

  // The service's report: its index.html.
  static std::string ReportHtml(const EvaluatorService& service) {
    return ReadFile(service.report_dir() + "/index.html");
  }
  // Whether the report has a file `name` of more than `min_bytes` bytes.
  static ::testing::AssertionResult HasReportFile(const EvaluatorService& service,
                                                  const std::string& name, uintmax_t min_bytes) {
    const std::string path = service.report_dir() + "/" + name;
    if (!std::filesystem::exists(path)) return ::testing::AssertionFailure() << "no " << path;
    const uintmax_t size = std::filesystem::file_size(path);
    if (size <= min_bytes) {
      return ::testing::AssertionFailure() << path << " has " << size << " bytes";
    }
    return ::testing::AssertionSuccess();
  }

  std::vector<std::string> JsonLines(const EvaluatorService& service) const {
    std::vector<std::string> lines;
    std::ifstream in(service.eval_jsonl_path());
    for (std::string line; std::getline(in, line);) lines.push_back(line);
    return lines;
  }

  TempDir dir_;
  // The run's checkpoint folder (Config().out_dir + "/checkpoints"): announced files are read
  // from it only.
  const std::string checkpoints_ = dir_ / "run-a/checkpoints";
  Bus bus_;
  std::vector<rlmsg::eval_result_t> results_;
  std::vector<rlmsg::stats_evaluator_t> stats_;
};

TEST_F(EvaluatorServiceTest, ScoresAnAnnouncedCheckpointAndPublishesTheResult) {
  EvaluatorService service(Config(), &bus_, nullptr);
  EXPECT_DOUBLE_EQ(service.goal(), 475.0);  // CartPole-v1's reward threshold
  Announce(WriteCheckpoint(1200), 1200);
  ASSERT_TRUE(PollUntil(&service, [&] { return !results_.empty(); }));

  const rlmsg::eval_result_t& r = results_.front();
  EXPECT_EQ(r.header.run_id, 77);
  ExpectMetadataOfUpdate(r, 1200);
  EXPECT_EQ(r.episodes, 5);
  EXPECT_GT(r.mean, 0.0);
  EXPECT_LT(r.mean, 20.0);
  EXPECT_LE(r.min, r.mean);
  EXPECT_GE(r.max, r.mean);
  EXPECT_EQ(r.goal_reached, 0);
  EXPECT_EQ(service.checkpoints_scored(), 1);

  // The history line and the report.
  const std::vector<std::string> lines = JsonLines(service);
  ASSERT_EQ(lines.size(), 1U);
  EvalRecord rec;
  ASSERT_TRUE(ParseJson(lines[0], &rec));
  EXPECT_EQ(rec.checkpoint, "ckpt-000001200.bin");
  EXPECT_EQ(rec.update, 1200);
  EXPECT_EQ(rec.mean, r.mean);
  const std::string html = ReportHtml(service);
  EXPECT_NE(html.find("ckpt-000001200.bin"), std::string::npos);
  EXPECT_NE(html.find("run-a"), std::string::npos);

  // Stats follow within a stats period.
  ASSERT_TRUE(PollUntil(&service, [&] {
    return !stats_.empty() && stats_.back().checkpoints_scored == 1 && stats_.back().busy == 0;
  }));
  EXPECT_EQ(stats_.back().best_update, 1200);
  EXPECT_DOUBLE_EQ(stats_.back().best_mean, r.mean);
  EXPECT_DOUBLE_EQ(stats_.back().last_mean, r.mean);
  EXPECT_EQ(service.FinalLine().rfind("evaluator: goal not reached (best ", 0), 0U);
}

TEST_F(EvaluatorServiceTest, ScoresNewBestCheckpointsOnTheSecondMetricToo) {
  EvaluatorConfig c = Config();
  c.second_env = "CartPole-v1";  // the same env, for a test: the seeds differ in count only
  c.second_episodes = 3;
  c.second_name = "three episodes";
  EvaluatorService service(c, &bus_, nullptr);
  ASSERT_TRUE(AnnounceUntilResults(&service, WriteCheckpoint(100), 100, 1));
  // The same policy again: not a new best, so not scored on the second metric.
  ASSERT_TRUE(AnnounceUntilResults(&service, WriteCheckpoint(200), 200, 2));
  const std::vector<std::string> lines = JsonLines(service);
  ASSERT_EQ(lines.size(), 2U);
  EvalRecord first, second;
  ASSERT_TRUE(ParseJson(lines[0], &first));
  ASSERT_TRUE(ParseJson(lines[1], &second));
  EXPECT_EQ(first.second_episodes, 3);
  EXPECT_GT(first.second_mean, 0.0);
  EXPECT_LT(first.second_mean, 20.0);
  EXPECT_EQ(second.second_episodes, 0);
  EXPECT_EQ(lines[1].find("second_mean"), std::string::npos);
  const std::string html = ReportHtml(service);
  EXPECT_NE(html.find("Second metric (new best checkpoints only): three episodes, 3 episodes"),
            std::string::npos);
  EXPECT_NE(html.find("second metric (update 100): "), std::string::npos);
}

TEST_F(EvaluatorServiceTest, ANewBestBelowTheSecondMetricsMinimumIsNotScoredOnIt) {
  EvaluatorConfig c = Config();
  c.second_env = "CartPole-v1";
  c.second_episodes = 3;
  c.second_name = "three episodes";
  c.second_min_mean = 1000;  // above any CartPole score
  EvaluatorService service(c, &bus_, nullptr);
  ASSERT_TRUE(AnnounceUntilResults(&service, WriteCheckpoint(100), 100, 1));
  const std::vector<std::string> lines = JsonLines(service);
  ASSERT_EQ(lines.size(), 1U);
  EXPECT_EQ(lines[0].find("second_mean"), std::string::npos) << lines[0];
  EXPECT_NE(ReportHtml(service).find("Second metric (new best checkpoints only): three episodes, "
                                     "3 episodes, for a standard mean of 1000 or more"),
            std::string::npos);
}

// Each checkpoint's ensemble with the one before it plays as one checkpoint of their mean action
// does, on the same episodes; the first checkpoint has none before it, so no ensemble.
TEST_F(EvaluatorServiceTest, ScoresEachCheckpointsEnsembleWithTheOnesBeforeIt) {
  const EvaluatorConfig c = EnsembleConfig("actions");
  std::FILE* progress = std::tmpfile();
  ASSERT_NE(progress, nullptr);
  EvaluatorService service(c, &bus_, progress);
  ASSERT_NO_FATAL_FAILURE(ScoreTwoConstantLanders(&service));
  ASSERT_EQ(service.records().size(), 2U);
  const EvalRecord& first = service.records()[0];
  const EvalRecord& second = service.records()[1];
  EXPECT_EQ(first.ensemble_size, 0);
  EXPECT_EQ(second.ensemble_size, 2);
  EXPECT_EQ(second.ensemble_from, 10);
  const EvalRecord mean_action = ScoreCheckpoint(ConstantLanderCheckpoint(7, 0.4f, -0.2f), "m.bin",
                                                 kLander, 2, 0.0, c.seed_base, c.gamma);
  EXPECT_EQ(second.ensemble_returns, mean_action.returns);
  EXPECT_DOUBLE_EQ(second.ensemble_mean, mean_action.mean);
  EXPECT_NE(second.ensemble_returns, second.returns);
  // In eval.jsonl, the report and its curves.
  const std::vector<std::string> lines = JsonLines(service);
  ASSERT_EQ(lines.size(), 2U);
  EXPECT_EQ(lines[0].find("ensemble_"), std::string::npos);
  EvalRecord read;
  ASSERT_TRUE(ParseJson(lines[1], &read));
  EXPECT_EQ(read, second);
  const std::string html = ReportHtml(service);
  EXPECT_TRUE(Contains(html, "Best ensemble"));
  EXPECT_TRUE(Contains(html, "the mean action of 2 checkpoints, updates 10 to 20"));
  EXPECT_TRUE(Contains(html, "<th>ensemble</th>"));
  EXPECT_TRUE(Contains(ReadFile(service.report_dir() + "/curve_env_steps.svg"), "ensemble of 2"));
  const std::string log = ReadAndClose(progress);
  EXPECT_TRUE(Contains(log, "update 10: no ensemble of 2: an ensemble of 2 needs 1 checkpoints"));
  EXPECT_TRUE(Contains(log, "update 20: ensemble of 2 (updates 10 to 20): mean "));
}

// By weights, the ensemble is the network of the members' mean weights (for these actors also
// their mean action); the best one is kept in the run's folder as a checkpoint file.
TEST_F(EvaluatorServiceTest, ScoresAndKeepsTheAverageOfEachCheckpointsWeights) {
  const EvaluatorConfig c = EnsembleConfig("weights");
  std::FILE* progress = std::tmpfile();
  ASSERT_NE(progress, nullptr);
  EvaluatorService service(c, &bus_, progress);
  ASSERT_NO_FATAL_FAILURE(ScoreTwoConstantLanders(&service));
  const EvalRecord second = service.records().back();
  EXPECT_EQ(second.ensemble_size, 2);
  EXPECT_EQ(second.ensemble_by, "weights");
  EXPECT_EQ(second.ensemble_from, 10);
  const EvalRecord mean_weights = ScoreCheckpoint(ConstantLanderCheckpoint(7, 0.4f, -0.2f), "m.bin",
                                                  kLander, 2, 0.0, c.seed_base, c.gamma);
  EXPECT_EQ(second.ensemble_returns, mean_weights.returns);
  const nn::Checkpoint kept = nn::LoadCheckpoint(c.out_dir + "/" + kBestAverageFile);
  EXPECT_EQ(kept.meta.update, 20);
  EXPECT_EQ(kept.params, AverageCheckpoints({ConstantLanderCheckpoint(20, 0.2f, 0.0f, 77),
                                             ConstantLanderCheckpoint(10, 0.6f, -0.4f, 77)},
                                            {"b", "a"})
                             .params);
  EvalRecord read;
  ASSERT_TRUE(ParseJson(JsonLines(service).back(), &read));
  EXPECT_EQ(read, second);
  const std::string html = ReportHtml(service);
  EXPECT_TRUE(Contains(html, "Best average"));
  EXPECT_TRUE(Contains(html, "the mean weights of 2 checkpoints, updates 10 to 20"));
  EXPECT_TRUE(Contains(html, "<th>average</th>"));
  EXPECT_TRUE(Contains(ReadFile(service.report_dir() + "/curve_env_steps.svg"), "average of 2"));
  // A better average replaces it (mean action (-0.4, 0.5)); an equal one later does not.
  ASSERT_TRUE(
      AnnounceUntilResults(&service, Save(ConstantLanderCheckpoint(30, -1.0f, 1.0f, 77)), 30, 3));
  ASSERT_GT(service.records().back().ensemble_mean, second.ensemble_mean);
  EXPECT_EQ(nn::LoadCheckpoint(c.out_dir + "/" + kBestAverageFile).meta.update, 30);
  ASSERT_TRUE(
      AnnounceUntilResults(&service, Save(ConstantLanderCheckpoint(40, 0.2f, 0.0f, 77)), 40, 4));
  ASSERT_EQ(service.records().back().ensemble_mean, service.records()[2].ensemble_mean);
  EXPECT_EQ(nn::LoadCheckpoint(c.out_dir + "/" + kBestAverageFile).meta.update, 30);
  EXPECT_TRUE(
      Contains(ReadAndClose(progress), "update 20: average of 2 (updates 10 to 20): mean "));
}

TEST_F(EvaluatorServiceTest, NoEnsembleBelowItsMinimumOrOfAnotherRunsCheckpoint) {
  EvaluatorConfig c = EnsembleConfig("actions");
  c.ensemble_min_mean = 1000;  // above any LunarLander score
  {
    EvaluatorService service(c, &bus_, nullptr);
    Save(ConstantLanderCheckpoint(10, 0.6f, -0.4f, 77));
    ASSERT_TRUE(
        AnnounceUntilResults(&service, Save(ConstantLanderCheckpoint(20, 0.2f, 0.0f, 77)), 20, 1));
    EXPECT_EQ(service.records().back().ensemble_size, 0);
  }
  c.ensemble_min_mean = -std::numeric_limits<double>::infinity();
  c.out_dir = (dir_ / "run-b").string();
  std::filesystem::create_directories(c.out_dir + "/checkpoints");
  EvaluatorService service(c, &bus_, nullptr);
  const std::string folder = c.out_dir + "/checkpoints/";
  nn::SaveCheckpoint(folder + nn::CheckpointFileName(10), ConstantLanderCheckpoint(10, 0, 0, 78));
  const std::string ours = folder + nn::CheckpointFileName(20);
  nn::SaveCheckpoint(ours, ConstantLanderCheckpoint(20, 0.2f, 0.0f, 77));
  ASSERT_TRUE(AnnounceUntilResults(&service, ours, 20, 2));
  EXPECT_EQ(service.records().back().ensemble_size, 0);
  EXPECT_EQ(service.records().back().update, 20);
}

TEST_F(EvaluatorServiceTest, RecordsAVideoOfEachNewBestCheckpointAndShowsItInTheReport) {
  EvaluatorService service(WithVideos(Config(), 96, 64), &bus_, nullptr);
  ASSERT_TRUE(AnnounceUntilResults(&service, WriteCheckpoint(100), 100, 1));
  ASSERT_TRUE(HasReportFile(service, "best.webm", 100));
  const std::string html = ReportHtml(service);
  EXPECT_NE(html.find("<video src=\"best.webm\""), std::string::npos);
  EXPECT_NE(html.find("ckpt-000000100.bin (update 100"), std::string::npos);
  // CartPole has no camera frames: no frame grid.
  EXPECT_FALSE(std::filesystem::exists(service.report_dir() + "/frames.png"));
  EXPECT_EQ(html.find("frames.png"), std::string::npos);
  // The same policy scores the same: no new best, so the video stays that of update 100.
  ASSERT_TRUE(AnnounceUntilResults(&service, WriteCheckpoint(200), 200, 2));
  EXPECT_NE(ReportHtml(service).find("ckpt-000000100.bin (update 100"), std::string::npos);
}

TEST_F(EvaluatorServiceTest, ShowsAGridOfCameraFramesForAPixelEnv) {
  EvaluatorService service(WithVideos(CatchConfig(), 64, 64), &bus_, nullptr);
  ASSERT_TRUE(AnnounceUntilResults(&service, Save(CatchCheckpoint(50)), 50, 1));
  ASSERT_TRUE(HasReportFile(service, "frames.png", 100));
  const std::string html = ReportHtml(service);
  EXPECT_NE(html.find("<img src=\"frames.png\""), std::string::npos);
  EXPECT_NE(html.find("4 greedy episodes"), std::string::npos);
}

TEST_F(EvaluatorServiceTest, DrawsATsneMapOfACheckpointAtTheGoalBeforeItsResult) {
  EvaluatorConfig c = CatchConfig();
  c.tsne = 100;
  c.goal = -10;  // every checkpoint reaches it
  std::FILE* log = std::tmpfile();
  ASSERT_NE(log, nullptr);
  EvaluatorService service(c, &bus_, log);
  ASSERT_TRUE(AnnounceUntilResults(&service, Save(CatchCheckpoint(50)), 50, 1));
  EXPECT_FALSE(service.tsne_map_due());
  EXPECT_GT(service.tsne_seconds(), 0.0);
  ASSERT_TRUE(HasReportFile(service, "tsne.png", 1000));
  const std::string html = ReportHtml(service);
  EXPECT_NE(html.find("<img src=\"tsne.png\""), std::string::npos);
  EXPECT_NE(html.find("in 100 states ("), std::string::npos);
  EXPECT_NE(html.find("of 12 greedy episodes"), std::string::npos);
  EXPECT_NE(html.find("max_a Q(s, a)"), std::string::npos);
  EXPECT_NE(html.find("ckpt-000000050.bin (update 50"), std::string::npos);
  // One line says what the map took.
  const std::string text = ReadAndClose(log);
  EXPECT_EQ(CountOccurrences(text, "evaluator: t-SNE map of "), 1) << text;
  EXPECT_TRUE(Contains(text,
                       "evaluator: t-SNE map of ckpt-000000050.bin (update 50): 100 states of 12 "
                       "greedy episodes ("));
}

TEST_F(EvaluatorServiceTest, KeepsTheTsneMapOfANewBestDueWhileTheTimeShareIsSpent) {
  EvaluatorConfig c = CatchConfig();
  c.tsne = 100;
  c.goal = 10;  // never reached
  EvaluatorService service(c, &bus_, nullptr);
  ASSERT_TRUE(AnnounceUntilResults(&service, Save(CatchCheckpoint(50)), 50, 1));
  // Its first map is expected to take kTsneFirstGuessSeconds, more than a fifth of the time the
  // service has run: due, not made.
  EXPECT_TRUE(service.tsne_map_due());
  EXPECT_EQ(service.tsne_seconds(), 0.0);
  EXPECT_FALSE(std::filesystem::exists(service.report_dir() + "/tsne.png"));
  EXPECT_EQ(ReportHtml(service).find("tsne.png"), std::string::npos);
}

TEST_F(EvaluatorServiceTest, RefusesATsneMapForAFlatEnv) {
  EvaluatorConfig c = Config();
  c.tsne = 2000;
  EXPECT_THROW(EvaluatorService(c, &bus_, nullptr), std::invalid_argument);
}

TEST_F(EvaluatorServiceTest, RefusesACorruptedCheckpointAndStillScoresTheNextGoodOne) {
  EvaluatorService service(Config(), &bus_, nullptr);
  // Flip one byte in the middle of a real checkpoint.
  const std::string good = WriteCheckpoint(100);
  const std::string bad = checkpoints_ + "/ckpt_corrupted.bin";
  std::filesystem::copy_file(good, bad);
  {
    std::fstream f(bad, std::ios::in | std::ios::out | std::ios::binary);
    f.seekg(0, std::ios::end);
    const std::streamoff size = f.tellg();
    f.seekg(size / 2);
    char c = 0;
    f.get(c);
    f.seekp(size / 2);
    f.put(static_cast<char>(c ^ 0x5A));
  }
  Announce(bad, 50);
  ASSERT_TRUE(PollUntil(&service, [&] { return service.checkpoints_refused() == 1; }));
  EXPECT_TRUE(results_.empty());
  EXPECT_TRUE(JsonLines(service).empty());
  EXPECT_EQ(service.checkpoints_scored(), 0);

  // A missing file is refused the same way.
  Announce(checkpoints_ + "/ckpt_missing.bin", 60);
  ASSERT_TRUE(PollUntil(&service, [&] { return service.checkpoints_refused() == 2; }));

  Announce(good, 100);
  ASSERT_TRUE(PollUntil(&service, [&] { return !results_.empty(); }));
  EXPECT_EQ(results_.front().update, 100);
  EXPECT_EQ(JsonLines(service).size(), 1U);
  EXPECT_EQ(service.checkpoints_refused(), 2);
}

// Whoever holds the run's key can announce any path: only regular files in the run's checkpoint
// folder are read. A checkpoint elsewhere, a symbolic link to it, a device that never ends and a
// FIFO that would block are refused and counted, and the service goes on to score the next good
// one. (A helper thread opens the FIFO for writing should the service block on it, so that the
// test fails instead of hanging.)
TEST_F(EvaluatorServiceTest, ReadsAnnouncedCheckpointsFromTheRunsCheckpointFolderOnly) {
  EvaluatorService service(Config(), &bus_, nullptr);
  const std::string outside = dir_ / "ckpt_7.bin";
  nn::SaveCheckpoint(outside, AlwaysLeftCheckpoint(7));
  std::filesystem::create_symlink(outside, checkpoints_ + "/ckpt_8.bin");
  const std::string fifo = checkpoints_ + "/ckpt_9.bin";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  {
    const FifoUnblocker unblock(fifo);
    int64_t update = 7;
    for (const std::string& path : {outside, checkpoints_ + "/ckpt_8.bin", fifo,
                                    checkpoints_ + "/../../ckpt_7.bin", std::string("/dev/zero")}) {
      const int64_t refused = service.checkpoints_refused();
      Announce(path, update++);
      EXPECT_TRUE(PollUntil(&service, [&] { return service.checkpoints_refused() == refused + 1; }))
          << path;
    }
  }
  EXPECT_TRUE(results_.empty());
  EXPECT_EQ(service.checkpoints_scored(), 0);
  Announce(WriteCheckpoint(100), 100);
  ASSERT_TRUE(PollUntil(&service, [&] { return !results_.empty(); }));
  EXPECT_EQ(results_.front().update, 100);
  ASSERT_TRUE(PollUntil(&service,
                        [&] { return !stats_.empty() && stats_.back().checkpoints_refused == 5; }));
}

TEST_F(EvaluatorServiceTest, RefusesANetworkThatDoesNotFitTheEnv) {
  EvaluatorService service(Config(), &bus_, nullptr);
  std::mt19937 rng(1);
  nn::Sequential wide = nn::MakeMlp(6, {8}, 3, &rng);
  nn::Checkpoint ckpt;
  ckpt.architecture = wide.Architecture();
  wide.GetFlat(&ckpt.params);
  const std::string path = checkpoints_ + "/wide.bin";
  nn::SaveCheckpoint(path, ckpt);
  Announce(path, 10);
  ASSERT_TRUE(PollUntil(&service, [&] { return service.checkpoints_refused() == 1; }));
  EXPECT_TRUE(results_.empty());
}

TEST_F(EvaluatorServiceTest, ScoresTheNewestFirstThenTheSupersededOnesNewestFirst) {
  EvaluatorService service(Config(), &bus_, nullptr);
  const std::string a = WriteCheckpoint(10), b = WriteCheckpoint(20), c = WriteCheckpoint(30);
  Announce(a, 10);
  Announce(c, 30);
  Announce(b, 20);  // arrives late, older than the pending one
  ASSERT_TRUE(PollUntil(&service, [&] { return results_.size() == 3; }));
  EXPECT_EQ(results_[0].update, 30);
  EXPECT_EQ(results_[1].update, 20);
  EXPECT_EQ(results_[2].update, 10);
  for (int i = 0; i < 5; ++i) service.Poll(5);
  EXPECT_EQ(results_.size(), 3U);
  EXPECT_EQ(service.checkpoints_skipped(), 0);
  EXPECT_EQ(service.backlog(), 0);
  EXPECT_FALSE(service.has_pending());
}

TEST_F(EvaluatorServiceTest, ANewerAnnouncementGoesBeforeTheBacklog) {
  EvaluatorService service(Config(), &bus_, nullptr);
  Announce(WriteCheckpoint(10), 10);
  Announce(WriteCheckpoint(20), 20);
  service.Poll(10);  // takes both announcements and scores update 20 ...
  ASSERT_EQ(service.checkpoints_scored(), 1);
  EXPECT_EQ(service.backlog(), 1);  // ... while update 10 waits
  Announce(WriteCheckpoint(30), 30);
  ASSERT_TRUE(PollUntil(&service, [&] { return results_.size() == 3; }));
  EXPECT_EQ(results_[0].update, 20);
  EXPECT_EQ(results_[1].update, 30);
  EXPECT_EQ(results_[2].update, 10);
}

TEST_F(EvaluatorServiceTest, SkipsSupersededCheckpointsWithoutABacklogOrWhoseFileIsGone) {
  EvaluatorConfig config = Config();
  config.backlog = 0;
  {
    EvaluatorService service(config, &bus_, nullptr);
    const std::string a = WriteCheckpoint(10), b = WriteCheckpoint(20), c = WriteCheckpoint(30);
    Announce(a, 10);
    Announce(c, 30);
    Announce(b, 20);
    ASSERT_TRUE(PollUntil(&service, [&] { return !results_.empty(); }));
    for (int i = 0; i < 5; ++i) service.Poll(5);
    ASSERT_EQ(results_.size(), 1U);
    EXPECT_EQ(results_.front().update, 30);
    EXPECT_EQ(service.checkpoints_skipped(), 2);
    ASSERT_TRUE(PollUntil(&service, [&] {
      return !stats_.empty() && stats_.back().checkpoints_skipped == 2 &&
             stats_.back().checkpoints_scored == 1;
    }));
  }
  // With a backlog: a superseded checkpoint the learner deleted before its turn is skipped
  // quietly, not refused. (A new service would queue the files the first one skipped: gone.)
  results_.clear();
  ASSERT_TRUE(std::filesystem::remove(checkpoints_ + "/ckpt-000000010.bin"));
  ASSERT_TRUE(std::filesystem::remove(checkpoints_ + "/ckpt-000000020.bin"));
  EvaluatorService service(Config(), &bus_, nullptr);
  const std::string d = WriteCheckpoint(40);
  Announce(d, 40);
  Announce(WriteCheckpoint(50), 50);
  service.Poll(10);  // scores update 50; update 40 waits
  ASSERT_EQ(service.checkpoints_scored(), 1);
  ASSERT_EQ(service.backlog(), 1);
  ASSERT_TRUE(std::filesystem::remove(d));
  for (int i = 0; i < 5; ++i) service.Poll(5);
  ASSERT_EQ(results_.size(), 1U);
  EXPECT_EQ(results_.front().update, 50);
  EXPECT_EQ(service.checkpoints_skipped(), 1);
  EXPECT_EQ(service.checkpoints_refused(), 0);
  EXPECT_EQ(service.backlog(), 0);
}

TEST_F(EvaluatorServiceTest, QueuesTheCheckpointsAnEarlierLifeLeftUnscored) {
  {
    EvaluatorService first(Config(), &bus_, nullptr);
    ASSERT_TRUE(AnnounceUntilResults(&first, WriteCheckpoint(10), 10, 1));
  }
  // Written after the first life ended (or announced to it and lost with its queue), beside
  // files that are not this run's checkpoints.
  WriteCheckpoint(20);
  WriteCheckpoint(25);
  WriteCheckpoint(30);
  nn::Checkpoint foreign = AlwaysLeftCheckpoint(40);
  foreign.meta.run_id = 78;
  Save(foreign);
  { std::ofstream(checkpoints_ + "/ckpt-000000050.bin") << "not a checkpoint"; }
  { std::ofstream(checkpoints_ + "/ckpt-000000060.bin.tmp.123") << "a write cut short"; }
  { std::ofstream(checkpoints_ + "/best.bin") << "a copy by hand"; }
  { std::ofstream(checkpoints_ + "/" + std::string(nn::kLearnerStateFile)) << "the learner's"; }
  Bus bus2(MemqConfig());
  std::FILE* log = std::tmpfile();
  ASSERT_NE(log, nullptr);
  EvaluatorConfig c = Config();
  c.backlog = 1;
  ::testing::internal::CaptureStderr();
  EvaluatorService second(c, &bus2, log);
  const std::string errors = ::testing::internal::GetCapturedStderr();
  // The file of a checkpoint's name that is not one is refused by name; the learner's state and
  // files of other names are passed over.
  EXPECT_TRUE(Contains(errors, "not queued: checkpoint " + checkpoints_ + "/ckpt-000000050.bin"))
      << errors;
  EXPECT_FALSE(Contains(errors, std::string(nn::kLearnerStateFile))) << errors;
  EXPECT_FALSE(Contains(errors, "best.bin")) << errors;
  EXPECT_TRUE(second.has_pending());
  EXPECT_EQ(second.backlog(), 1);
  EXPECT_EQ(second.checkpoints_skipped(), 1);  // the oldest, 20, beyond the backlog
  ASSERT_TRUE(PollUntil(&second, [&] { return second.checkpoints_scored() == 2; }));
  ASSERT_EQ(second.records().size(), 3U);
  EXPECT_EQ(second.records()[1].update, 30);  // the newest first
  ExpectMetadataOfUpdate(second.records()[1], 30);
  EXPECT_EQ(second.records()[2].update, 25);
  EXPECT_EQ(second.checkpoints_refused(), 0);
  EXPECT_TRUE(Contains(ReadAndClose(log), "evaluator: 3 unscored checkpoints found in " +
                                              checkpoints_ +
                                              ", 1 of them beyond the backlog skipped\n"));
}

TEST_F(EvaluatorServiceTest, StopsAtTheGoalWhenAsked) {
  EvaluatorConfig config = Config();
  config.goal = 5;  // the always-left policy lasts about nine steps
  config.stop_at_goal = true;
  EvaluatorService service(config, &bus_, nullptr);
  Announce(WriteCheckpoint(7), 7);
  bool stop = false;
  for (int i = 0; i < 200 && !stop; ++i) stop = service.Poll(10);
  EXPECT_TRUE(stop);
  // The result was published before Poll returned; deliver it to our subscription.
  for (int i = 0; i < 20 && results_.empty(); ++i) bus_.Handle(10);
  ASSERT_EQ(results_.size(), 1U);
  EXPECT_EQ(results_.front().goal_reached, 1);
  EXPECT_TRUE(service.goal_reached());
  EXPECT_EQ(service.FinalLine(), "evaluator: goal reached");
  const std::string html = ReportHtml(service);
  EXPECT_NE(html.find("badge yes\">reached"), std::string::npos);
}

TEST_F(EvaluatorServiceTest, ARestartedServiceKeepsTheHistoryAndIgnoresRepeats) {
  const std::string path = WriteCheckpoint(40);
  {
    EvaluatorService first(Config(), &bus_, nullptr);
    ASSERT_TRUE(AnnounceUntilResults(&first, path, 40, 1));
  }
  // The restarted service gets a bus of its own, as a new process would.
  Bus bus2(MemqConfig());
  EvaluatorService second(Config(), &bus2, nullptr);
  ASSERT_EQ(second.records().size(), 1U);
  EXPECT_EQ(second.records()[0].update, 40);
  EXPECT_EQ(second.checkpoints_scored(), 0);
  ASSERT_NE(second.best(), nullptr);

  // Announcing the scored checkpoint again changes nothing.
  rlmsg::checkpoint_t m{};
  m.path = path;
  m.update = 40;
  ASSERT_TRUE(bus2.Publish(channels::kCheckpoint, &m));
  for (int i = 0; i < 10; ++i) second.Poll(5);
  EXPECT_EQ(second.duplicates_ignored(), 1);
  EXPECT_EQ(second.checkpoints_scored(), 0);
  const std::string html = ReportHtml(second);
  EXPECT_EQ(CountOccurrences(html, "<td>ckpt-000000040.bin</td>"), 1);
}

TEST_F(EvaluatorServiceTest, ARestartedServiceKeepsItsBestsMediaAndScoresNoWorseOneAsABest) {
  EvaluatorConfig c = WithVideos(Config(), 96, 64);
  c.second_env = "CartPole-v1";
  c.second_episodes = 3;
  {
    EvaluatorService first(c, &bus_, nullptr);
    ASSERT_TRUE(AnnounceUntilResults(&first, Save(BalancingCheckpoint(100)), 100, 1));
  }
  Bus bus2(MemqConfig());
  EvaluatorService second(c, &bus2, nullptr);
  // Before it scores anything, its report shows the video of the first life's best.
  EXPECT_TRUE(Contains(ReportHtml(second), "<video src=\"best.webm\""));
  EXPECT_TRUE(Contains(ReportHtml(second), "ckpt-000000100.bin (update 100"));
  // A worse checkpoint is no new best: no second metric, and the video stays that of update 100.
  rlmsg::checkpoint_t m{};
  m.path = WriteCheckpoint(200);
  m.update = 200;
  ASSERT_TRUE(bus2.Publish(channels::kCheckpoint, &m));
  ASSERT_TRUE(PollUntil(&second, [&] { return second.checkpoints_scored() == 1; }));
  const std::vector<std::string> lines = JsonLines(second);
  ASSERT_EQ(lines.size(), 2U);
  EXPECT_NE(lines[0].find("second_mean"), std::string::npos);
  EXPECT_EQ(lines[1].find("second_mean"), std::string::npos);
  const std::string html = ReportHtml(second);
  EXPECT_TRUE(Contains(html, "ckpt-000000100.bin (update 100"));
  EXPECT_EQ(html.find("ckpt-000000200.bin (update 200"), std::string::npos);
}

TEST_F(EvaluatorServiceTest, ARestartedServiceShowsItsBestsFrameGridAndTsneMap) {
  EvaluatorConfig c = WithVideos(CatchConfig(), 64, 64);
  c.tsne = 100;
  c.goal = -10;  // reached: the map is made before the result
  {
    EvaluatorService first(c, &bus_, nullptr);
    ASSERT_TRUE(AnnounceUntilResults(&first, Save(CatchCheckpoint(50)), 50, 1));
    ASSERT_TRUE(HasReportFile(first, "tsne.png", 1000));
  }
  Bus bus2(MemqConfig());
  EvaluatorService second(c, &bus2, nullptr);
  std::string html = ReportHtml(second);
  EXPECT_TRUE(Contains(html, "<img src=\"frames.png\""));
  EXPECT_TRUE(Contains(html, "<img src=\"tsne.png\""));
  EXPECT_TRUE(Contains(html, "ckpt-000000050.bin (update 50"));
  // The same policy scores the same: no new best, no new map.
  rlmsg::checkpoint_t m{};
  m.path = Save(CatchCheckpoint(60));
  m.update = 60;
  ASSERT_TRUE(bus2.Publish(channels::kCheckpoint, &m));
  ASSERT_TRUE(PollUntil(&second, [&] { return second.checkpoints_scored() == 1; }));
  EXPECT_FALSE(second.tsne_map_due());
  EXPECT_EQ(second.tsne_seconds(), 0.0);
  html = ReportHtml(second);
  EXPECT_TRUE(Contains(html, "<img src=\"tsne.png\""));
  EXPECT_EQ(html.find("ckpt-000000060.bin (update 60"), std::string::npos);
}

TEST(CaptionTest, IsThatOfTheMediaFileAsItWasWhenCaptioned) {
  TempDir dir;
  const std::string media = dir / "best.webm";
  EXPECT_THROW(WriteCaption(media, "a caption"), std::runtime_error);  // no media file
  EXPECT_EQ(ReadCaption(media), "");
  { std::ofstream(media) << "video"; }
  EXPECT_EQ(ReadCaption(media), "");  // no caption
  WriteCaption(media, "a caption\nof two lines");
  EXPECT_EQ(ReadCaption(media), "a caption\nof two lines");
  // The media file rewritten (an evaluator killed before it wrote the new caption): not shown.
  { std::ofstream(media) << "another video"; }
  EXPECT_EQ(ReadCaption(media), "");
  std::filesystem::remove(media);
  EXPECT_EQ(ReadCaption(media), "");
}

TEST_F(EvaluatorServiceTest, ProgressLinesGoToTheGivenStream) {
  std::FILE* out = std::tmpfile();
  ASSERT_NE(out, nullptr);
  {
    EvaluatorService service(Config(), &bus_, out);
    Announce(WriteCheckpoint(5), 5);
    ASSERT_TRUE(PollUntil(&service, [&] { return !results_.empty(); }));
  }
  const std::string text = ReadAndClose(out);
  EXPECT_TRUE(Contains(text, "evaluator: update 5, env steps 20"));
  EXPECT_TRUE(Contains(text, "mean "));
}

// The screen decides which checkpoints get the full evaluation; every score published or written
// is a full evaluation (5 episodes here), never the screen's.
TEST_F(EvaluatorServiceTest, AScreenedOutCheckpointIsNeverScoredAndOneThatPassesGetsTheFullCount) {
  std::FILE* out = std::tmpfile();
  ASSERT_NE(out, nullptr);
  EvaluatorConfig config = ScreenConfig();
  config.screen_margin = 50;
  EvaluatorService service(config, &bus_, out);
  // The first checkpoint has no best to be screened against: full evaluation.
  ASSERT_TRUE(AnnounceUntilResults(&service, Save(BalancingCheckpoint(100)), 100, 1));
  const double best = results_.back().mean;
  ASSERT_GT(best, 100.0);  // far above the always-left policy's nine steps
  // Always left lasts about nine steps: below best - 50 on the screen, so not scored.
  Announce(WriteCheckpoint(200), 200);
  ASSERT_TRUE(PollUntil(&service, [&] { return service.checkpoints_screened_out() == 1; }));
  for (int i = 0; i < 5; ++i) service.Poll(5);
  EXPECT_EQ(results_.size(), 1U);
  EXPECT_EQ(service.checkpoints_scored(), 1);
  EXPECT_EQ(JsonLines(service).size(), 1U);
  // A balancing checkpoint passes the screen and gets all 5 episodes, the same score as
  // unscreened (the same seeds from the first).
  const std::string passing = Save(BalancingCheckpoint(300));
  ASSERT_TRUE(AnnounceUntilResults(&service, passing, 300, 2));
  EXPECT_EQ(results_.back().update, 300);
  EXPECT_EQ(results_.back().episodes, 5);
  const EvalRecord unscreened = ScoreCheckpointFile(passing, config.env_id, config.episodes,
                                                    config.epsilon, config.seed_base, config.gamma);
  EXPECT_EQ(results_.back().mean, unscreened.mean);
  for (const rlmsg::eval_result_t& r : results_) EXPECT_EQ(r.episodes, config.episodes);
  const std::vector<std::string> lines = JsonLines(service);
  ASSERT_EQ(lines.size(), 2U);
  for (const std::string& line : lines) {
    EvalRecord rec;
    ASSERT_TRUE(ParseJson(line, &rec));
    EXPECT_NE(rec.update, 200);
    EXPECT_EQ(rec.episodes, config.episodes);
  }
  EXPECT_TRUE(Contains(ReadAndClose(out),
                       "evaluator: update 200, env steps 800: screened out, not scored (mean of 2 "
                       "episodes"));
}

TEST_F(EvaluatorServiceTest, AfterTheMostScreenFailuresInARowTheNextCheckpointIsScoredInFull) {
  EvaluatorConfig config = ScreenConfig();
  config.screen_max_rejects = 2;
  EvaluatorService service(config, &bus_, nullptr);
  ASSERT_TRUE(AnnounceUntilResults(&service, Save(BalancingCheckpoint(100)), 100, 1));
  for (int64_t update : {200, 300}) {
    Announce(WriteCheckpoint(update), update);
    ASSERT_TRUE(PollUntil(&service,
                          [&] { return service.checkpoints_screened_out() == update / 100 - 1; }));
  }
  // Two failures in a row: the third always-left checkpoint is evaluated in full, unscreened.
  ASSERT_TRUE(AnnounceUntilResults(&service, WriteCheckpoint(400), 400, 2));
  EXPECT_EQ(results_.back().update, 400);
  EXPECT_EQ(results_.back().episodes, 5);
  EXPECT_LT(results_.back().mean, 20.0);
  EXPECT_EQ(service.checkpoints_screened_out(), 2);
  // And the count starts again: the next poor one is screened out.
  Announce(WriteCheckpoint(500), 500);
  ASSERT_TRUE(PollUntil(&service, [&] { return service.checkpoints_screened_out() == 3; }));
  EXPECT_EQ(results_.size(), 2U);
}

TEST_F(EvaluatorServiceTest, AnnouncementsAfterTheServiceIsGoneAreHarmless) {
  { EvaluatorService service(Config(), &bus_, nullptr); }
  Announce(WriteCheckpoint(3), 3);
  EXPECT_GE(bus_.Handle(50), 1);
  EXPECT_TRUE(results_.empty());
  EXPECT_EQ(bus_.counters().invalid, 0);
}

TEST(EvaluatorConfigTest, RejectsBadScreenSettings) {
  EvaluatorConfig c;
  c.screen_episodes = 10;
  EXPECT_NO_THROW(c.Validate());
  c.screen_episodes = c.episodes;  // a screen as long as the evaluation saves nothing
  EXPECT_THROW(c.Validate(), std::invalid_argument);
  c.screen_episodes = -1;
  EXPECT_THROW(c.Validate(), std::invalid_argument);
  c.screen_episodes = 10;
  c.screen_margin = -1;
  EXPECT_THROW(c.Validate(), std::invalid_argument);
  c.screen_margin = 0;
  c.screen_max_rejects = 0;
  EXPECT_THROW(c.Validate(), std::invalid_argument);
}

TEST(EvaluatorConfigTest, RejectsBadSettings) {
  EvaluatorConfig c;
  EXPECT_NO_THROW(c.Validate());
  c.episodes = 0;
  EXPECT_THROW(c.Validate(), std::invalid_argument);
  c = EvaluatorConfig();
  c.epsilon = 2;
  EXPECT_THROW(c.Validate(), std::invalid_argument);
  c = EvaluatorConfig();
  c.gamma = 1.01;
  EXPECT_THROW(c.Validate(), std::invalid_argument);
  c = EvaluatorConfig();
  c.tsne = 99;  // a map needs at least 100 states
  EXPECT_THROW(c.Validate(), std::invalid_argument);
  c.tsne = 5001;
  EXPECT_THROW(c.Validate(), std::invalid_argument);
  c.tsne = 2000;
  EXPECT_NO_THROW(c.Validate());
  c = EvaluatorConfig();
  c.second_env = "LunarLander-v3";  // other observations and actions than CartPole-v1's
  EXPECT_THROW(c.Validate(), std::invalid_argument);
  c.second_env = "CartPole-v1";
  EXPECT_NO_THROW(c.Validate());
  c.second_episodes = 0;
  EXPECT_THROW(c.Validate(), std::invalid_argument);
  c = EvaluatorConfig();
  c.ensemble = 0;
  EXPECT_THROW(c.Validate(), std::invalid_argument);
  c.ensemble = 2;  // CartPole-v1's actions are discrete: no mean action
  EXPECT_THROW(c.Validate(), std::invalid_argument);
  c.ensemble_by = "weights";  // but a mean of weights
  EXPECT_NO_THROW(c.Validate());
  c.ensemble_by = "votes";
  EXPECT_THROW(c.Validate(), std::invalid_argument);
  c.ensemble_by = "actions";
  c.env_id = kLander;
  EXPECT_NO_THROW(c.Validate());
  c.ensemble_min_mean = std::nan("");
  EXPECT_THROW(c.Validate(), std::invalid_argument);
}

TEST(ScoreCheckpointFileTest, ReadsTheMetadataAndRefusesATruncatedFile) {
  TempDir dir;
  const std::string path = dir / "c.bin";
  nn::SaveCheckpoint(path, AlwaysLeftCheckpoint(9));
  const EvalRecord r = ScoreCheckpointFile(path, "CartPole-v1", 3, 0.0, 1000);
  EXPECT_EQ(r.checkpoint, "c.bin");
  ExpectMetadataOfUpdate(r, 9);
  EXPECT_EQ(r.episodes, 3);
  // The network's values of the actions taken, against the returns of the (short) episodes.
  EXPECT_GT(r.value_steps, 3);
  EXPECT_DOUBLE_EQ(r.value_estimate, 1.0);
  EXPECT_GT(r.value_return, 1.0);
  std::filesystem::resize_file(path, std::filesystem::file_size(path) - 7);
  EXPECT_THROW(ScoreCheckpointFile(path, "CartPole-v1", 3, 0.0, 1000), std::runtime_error);
}

}  // namespace
}  // namespace rl::evaluator
