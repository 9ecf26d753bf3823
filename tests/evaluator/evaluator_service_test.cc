#include "evaluator/evaluator_service.h"

#include <sys/stat.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "common/channels.h"
#include "common/lcm_bus.h"
#include "nn/checkpoint.h"
#include "nn/linear.h"
#include "nn/sequential.h"
#include "temp_dir.h"

namespace rl::evaluator {
namespace {

using testing::CountOccurrences;
using testing::FifoUnblocker;
using testing::ReadFile;
using testing::TempDir;

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
    c.out_dir = dir_.path() + "/run-a";
    c.run_config_text = "env = CartPole-v1\n";
    return c;
  }

  std::string WriteCheckpoint(int64_t update) {
    std::string path = checkpoints_ + "/ckpt_" + std::to_string(update) + ".bin";
    nn::SaveCheckpoint(path, AlwaysLeftCheckpoint(update));
    return path;
  }

  std::string WriteBalancingCheckpoint(int64_t update) {
    std::string path = checkpoints_ + "/ckpt_" + std::to_string(update) + ".bin";
    nn::SaveCheckpoint(path, BalancingCheckpoint(update));
    return path;
  }

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
  EXPECT_EQ(r.update, 1200);
  EXPECT_EQ(r.env_steps, 4800);
  EXPECT_DOUBLE_EQ(r.wall_seconds, 12.0);
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
  EXPECT_EQ(rec.checkpoint, "ckpt_1200.bin");
  EXPECT_EQ(rec.update, 1200);
  EXPECT_EQ(rec.mean, r.mean);
  const std::string html = ReadFile(service.report_dir() + "/index.html");
  EXPECT_NE(html.find("ckpt_1200.bin"), std::string::npos);
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
  Announce(WriteCheckpoint(100), 100);
  ASSERT_TRUE(PollUntil(&service, [&] { return results_.size() == 1; }));
  // The same policy again: not a new best, so not scored on the second metric.
  Announce(WriteCheckpoint(200), 200);
  ASSERT_TRUE(PollUntil(&service, [&] { return results_.size() == 2; }));
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
  const std::string html = ReadFile(service.report_dir() + "/index.html");
  EXPECT_NE(html.find("Second metric (new best checkpoints only): three episodes, 3 episodes"),
            std::string::npos);
  EXPECT_NE(html.find("second metric (update 100): "), std::string::npos);
}

TEST_F(EvaluatorServiceTest, RecordsAVideoOfEachNewBestCheckpointAndShowsItInTheReport) {
  EvaluatorConfig c = Config();
  c.videos = true;
  c.video_width = 96;
  c.video_height = 64;
  EvaluatorService service(c, &bus_, nullptr);
  Announce(WriteCheckpoint(100), 100);
  ASSERT_TRUE(PollUntil(&service, [&] { return results_.size() == 1; }));
  const std::string video = service.report_dir() + "/best.webm";
  ASSERT_TRUE(std::filesystem::exists(video));
  EXPECT_GT(std::filesystem::file_size(video), 100U);
  const std::string html = ReadFile(service.report_dir() + "/index.html");
  EXPECT_NE(html.find("<video src=\"best.webm\""), std::string::npos);
  EXPECT_NE(html.find("ckpt_100.bin (update 100"), std::string::npos);
  // CartPole has no camera frames: no frame grid.
  EXPECT_FALSE(std::filesystem::exists(service.report_dir() + "/frames.png"));
  EXPECT_EQ(html.find("frames.png"), std::string::npos);
  // The same policy scores the same: no new best, so the video stays that of update 100.
  Announce(WriteCheckpoint(200), 200);
  ASSERT_TRUE(PollUntil(&service, [&] { return results_.size() == 2; }));
  EXPECT_NE(ReadFile(service.report_dir() + "/index.html").find("ckpt_100.bin (update 100"),
            std::string::npos);
}

TEST_F(EvaluatorServiceTest, ShowsAGridOfCameraFramesForAPixelEnv) {
  EvaluatorConfig c = Config();
  c.env_id = "Catch-v0+pixels(width=5,height=10,stack=2)";
  c.videos = true;
  c.video_width = 64;
  c.video_height = 64;
  std::mt19937 rng(5);
  nn::Sequential net = nn::MakeMlp(2 * 10 * 5, {8}, 3, &rng);
  nn::Checkpoint ckpt;
  ckpt.architecture = net.Architecture();
  net.GetFlat(&ckpt.params);
  ckpt.meta.update = 50;
  ckpt.meta.run_id = 77;
  const std::string path = checkpoints_ + "/ckpt_50.bin";
  nn::SaveCheckpoint(path, ckpt);
  EvaluatorService service(c, &bus_, nullptr);
  Announce(path, 50);
  ASSERT_TRUE(PollUntil(&service, [&] { return results_.size() == 1; }));
  const std::string frames = service.report_dir() + "/frames.png";
  ASSERT_TRUE(std::filesystem::exists(frames));
  EXPECT_GT(std::filesystem::file_size(frames), 100U);
  const std::string html = ReadFile(service.report_dir() + "/index.html");
  EXPECT_NE(html.find("<img src=\"frames.png\""), std::string::npos);
  EXPECT_NE(html.find("4 greedy episodes"), std::string::npos);
}

// A Catch checkpoint of a random MLP (a hidden layer of 8).
std::string WriteCatchCheckpoint(const std::string& folder, int64_t update) {
  std::mt19937 rng(5);
  nn::Sequential net = nn::MakeMlp(2 * 10 * 5, {8}, 3, &rng);
  nn::Checkpoint ckpt;
  ckpt.architecture = net.Architecture();
  net.GetFlat(&ckpt.params);
  ckpt.meta.update = update;
  ckpt.meta.run_id = 77;
  std::string path = folder + "/ckpt_" + std::to_string(update) + ".bin";
  nn::SaveCheckpoint(path, ckpt);
  return path;
}

TEST_F(EvaluatorServiceTest, DrawsATsneMapOfACheckpointAtTheGoalBeforeItsResult) {
  EvaluatorConfig c = Config();
  c.env_id = "Catch-v0+pixels(width=5,height=10,stack=2)";
  c.tsne = 100;
  c.goal = -10;  // every checkpoint reaches it
  std::FILE* log = std::tmpfile();
  ASSERT_NE(log, nullptr);
  EvaluatorService service(c, &bus_, log);
  Announce(WriteCatchCheckpoint(checkpoints_, 50), 50);
  ASSERT_TRUE(PollUntil(&service, [&] { return results_.size() == 1; }));
  EXPECT_FALSE(service.tsne_map_due());
  EXPECT_GT(service.tsne_seconds(), 0.0);
  const std::string map = service.report_dir() + "/tsne.png";
  ASSERT_TRUE(std::filesystem::exists(map));
  EXPECT_GT(std::filesystem::file_size(map), 1000U);
  const std::string html = ReadFile(service.report_dir() + "/index.html");
  EXPECT_NE(html.find("<img src=\"tsne.png\""), std::string::npos);
  EXPECT_NE(html.find("in 100 states ("), std::string::npos);
  EXPECT_NE(html.find("of 12 greedy episodes"), std::string::npos);
  EXPECT_NE(html.find("max_a Q(s, a)"), std::string::npos);
  EXPECT_NE(html.find("ckpt_50.bin (update 50"), std::string::npos);
  // One line says what the map took.
  std::rewind(log);
  std::string text(4096, '\0');
  text.resize(std::fread(text.data(), 1, text.size(), log));
  std::fclose(log);
  EXPECT_NE(text.find("evaluator: t-SNE map of ckpt_50.bin (update 50): 100 states of 12 greedy "
                      "episodes ("),
            std::string::npos)
      << text;
}

TEST_F(EvaluatorServiceTest, KeepsTheTsneMapOfANewBestDueWhileTheTimeShareIsSpent) {
  EvaluatorConfig c = Config();
  c.env_id = "Catch-v0+pixels(width=5,height=10,stack=2)";
  c.tsne = 100;
  c.goal = 10;  // never reached
  EvaluatorService service(c, &bus_, nullptr);
  Announce(WriteCatchCheckpoint(checkpoints_, 50), 50);
  ASSERT_TRUE(PollUntil(&service, [&] { return results_.size() == 1; }));
  // Its first map is expected to take kTsneFirstGuessSeconds, more than a fifth of the time the
  // service has run: due, not made.
  EXPECT_TRUE(service.tsne_map_due());
  EXPECT_EQ(service.tsne_seconds(), 0.0);
  EXPECT_FALSE(std::filesystem::exists(service.report_dir() + "/tsne.png"));
  EXPECT_EQ(ReadFile(service.report_dir() + "/index.html").find("tsne.png"), std::string::npos);
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

TEST_F(EvaluatorServiceTest, ScoresOnlyTheNewestOfSeveralUnscoredCheckpoints) {
  EvaluatorService service(Config(), &bus_, nullptr);
  const std::string a = WriteCheckpoint(10), b = WriteCheckpoint(20), c = WriteCheckpoint(30);
  Announce(a, 10);
  Announce(c, 30);
  Announce(b, 20);  // arrives late, older than the pending one
  ASSERT_TRUE(PollUntil(&service, [&] { return !results_.empty(); }));
  for (int i = 0; i < 5; ++i) service.Poll(5);
  ASSERT_EQ(results_.size(), 1U);
  EXPECT_EQ(results_.front().update, 30);
  EXPECT_EQ(service.checkpoints_skipped(), 2);
  EXPECT_FALSE(service.has_pending());
  ASSERT_TRUE(PollUntil(&service, [&] {
    return !stats_.empty() && stats_.back().checkpoints_skipped == 2 &&
           stats_.back().checkpoints_scored == 1;
  }));
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
  const std::string html = ReadFile(service.report_dir() + "/index.html");
  EXPECT_NE(html.find("badge yes\">reached"), std::string::npos);
}

TEST_F(EvaluatorServiceTest, ARestartedServiceKeepsTheHistoryAndIgnoresRepeats) {
  const std::string path = WriteCheckpoint(40);
  {
    EvaluatorService first(Config(), &bus_, nullptr);
    Announce(path, 40);
    ASSERT_TRUE(PollUntil(&first, [&] { return results_.size() == 1; }));
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
  const std::string html = ReadFile(second.report_dir() + "/index.html");
  EXPECT_EQ(CountOccurrences(html, "<td>ckpt_40.bin</td>"), 1);
}

TEST_F(EvaluatorServiceTest, ProgressLinesGoToTheGivenStream) {
  std::FILE* out = std::tmpfile();
  ASSERT_NE(out, nullptr);
  {
    EvaluatorService service(Config(), &bus_, out);
    Announce(WriteCheckpoint(5), 5);
    ASSERT_TRUE(PollUntil(&service, [&] { return !results_.empty(); }));
  }
  std::rewind(out);
  std::string text;
  for (int ch; (ch = std::fgetc(out)) != EOF;) text += static_cast<char>(ch);
  std::fclose(out);
  EXPECT_NE(text.find("evaluator: update 5, env steps 20"), std::string::npos) << text;
  EXPECT_NE(text.find("mean "), std::string::npos) << text;
}

// The screen decides which checkpoints get the full evaluation; every score published or written
// is a full evaluation (5 episodes here), never the screen's.
TEST_F(EvaluatorServiceTest, AScreenedOutCheckpointIsNeverScoredAndOneThatPassesGetsTheFullCount) {
  std::FILE* out = std::tmpfile();
  ASSERT_NE(out, nullptr);
  EvaluatorConfig config = Config();
  config.screen_episodes = 2;
  config.screen_margin = 50;
  EvaluatorService service(config, &bus_, out);
  // The first checkpoint has no best to be screened against: full evaluation.
  Announce(WriteBalancingCheckpoint(100), 100);
  ASSERT_TRUE(PollUntil(&service, [&] { return results_.size() == 1; }));
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
  const std::string passing = WriteBalancingCheckpoint(300);
  Announce(passing, 300);
  ASSERT_TRUE(PollUntil(&service, [&] { return results_.size() == 2; }));
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
  std::rewind(out);
  std::string text;
  for (int ch; (ch = std::fgetc(out)) != EOF;) text += static_cast<char>(ch);
  std::fclose(out);
  EXPECT_NE(text.find("evaluator: update 200, env steps 800: screened out, not scored (mean of 2 "
                      "episodes"),
            std::string::npos)
      << text;
}

TEST_F(EvaluatorServiceTest, AfterTheMostScreenFailuresInARowTheNextCheckpointIsScoredInFull) {
  EvaluatorConfig config = Config();
  config.screen_episodes = 2;
  config.screen_max_rejects = 2;
  EvaluatorService service(config, &bus_, nullptr);
  Announce(WriteBalancingCheckpoint(100), 100);
  ASSERT_TRUE(PollUntil(&service, [&] { return results_.size() == 1; }));
  for (int64_t update : {200, 300}) {
    Announce(WriteCheckpoint(update), update);
    ASSERT_TRUE(PollUntil(&service,
                          [&] { return service.checkpoints_screened_out() == update / 100 - 1; }));
  }
  // Two failures in a row: the third always-left checkpoint is evaluated in full, unscreened.
  Announce(WriteCheckpoint(400), 400);
  ASSERT_TRUE(PollUntil(&service, [&] { return results_.size() == 2; }));
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
}

TEST(ScoreCheckpointFileTest, ReadsTheMetadataAndRefusesATruncatedFile) {
  TempDir dir;
  const std::string path = dir / "c.bin";
  nn::SaveCheckpoint(path, AlwaysLeftCheckpoint(9));
  const EvalRecord r = ScoreCheckpointFile(path, "CartPole-v1", 3, 0.0, 1000);
  EXPECT_EQ(r.checkpoint, "c.bin");
  EXPECT_EQ(r.update, 9);
  EXPECT_EQ(r.env_steps, 36);
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
