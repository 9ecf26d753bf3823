#include "learner/learner.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <random>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "common/channels.h"
#include "learner/parameter_average.h"
#include "nn/checkpoint.h"
#include "nn/parallel.h"
#include "nn/precision.h"
#include "rlmsg/checkpoint_t.hpp"
#include "rlmsg/priority_update_t.hpp"
#include "rlmsg/sample_request_t.hpp"
#include "rlmsg/stats_learner_t.hpp"
#include "rlmsg/weights_chunk_t.hpp"
#include "tests/common/temp_dir.h"

namespace rl::learner {
namespace {

namespace fs = std::filesystem;

// Runs a Learner against a stand-in replay on the same in-process bus: every request is answered
// with random CartPole-shaped transitions. The first delivery of request 0 is "lost", and no
// request is answered until the learner has sent request 0 again, so the retry must happen.
class LearnerTest : public TempDirTest {
 protected:
  // The weights the learner broadcasts from now on, by version (the CartPole net is one chunk).
  std::map<int64_t, std::vector<float>>& RecordWeights() {
    bus_->Subscribe<rlmsg::weights_chunk_t>(
        channels::kWeights,
        [this](const rlmsg::weights_chunk_t& m) {
          ASSERT_EQ(m.num_chunks, 1);
          weights_[m.version] = m.data;
        },
        Port::kBulk);
    return weights_;
  }

  // A short run against this fixture's replay: `max_updates` updates on batches of `batch_size`,
  // a checkpoint every `checkpoint_every` updates into the scratch folder, lost replies retried
  // after 50 ms.
  LearnerConfig ShortRun(int batch_size, int max_updates, int checkpoint_every = 1000) const {
    LearnerConfig c;
    c.batch_size = batch_size;
    c.max_updates = max_updates;
    c.checkpoint_every = checkpoint_every;
    c.request_timeout = 0.05;
    c.out_dir = dir_.string();
    return c;
  }

  // ShortRun of a TD3 with two hidden layers of 16 on Pendulum-v1; the replies become
  // 3-float observations and one-float torques.
  LearnerConfig ShortTd3PendulumRun(int batch_size, int max_updates, int checkpoint_every) {
    obs_size_ = 3;
    continuous_ = true;
    LearnerConfig c = ShortRun(batch_size, max_updates, checkpoint_every);
    c.env_id = "Pendulum-v1";
    c.algorithm = "td3";
    c.Get<Td3Config>().hidden = {16, 16};
    return c;
  }

  LearnerTest() {
    bus_ = std::make_unique<Bus>(InProcessBusConfig(9, "learner"));
    bus_->Subscribe<rlmsg::sample_request_t>(
        channels::kSampleRequest, [this](const rlmsg::sample_request_t& r) { Answer(r); });
    bus_->Subscribe<rlmsg::checkpoint_t>(
        channels::kCheckpoint,
        [this](const rlmsg::checkpoint_t& m) { announced_.push_back(m.path); });
    bus_->Subscribe<rlmsg::weights_chunk_t>(
        channels::kWeights,
        [this](const rlmsg::weights_chunk_t& m) { versions_.insert(m.version); }, Port::kBulk);
  }

  void Answer(const rlmsg::sample_request_t& r) {
    ++requests_seen_;
    if (r.request_id == 0 && !dropped_first_) {
      dropped_first_ = true;
      return;
    }
    if (!retried_) {
      if (r.request_id != 0) {
        held_.push_back(r);
        return;
      }
      retried_ = true;
      Reply(r);
      for (const auto& h : held_) Reply(h);
      return;
    }
    Reply(r);
  }

  void Reply(const rlmsg::sample_request_t& r) {
    if (pixels_) {
      ReplyPixels(r);
      return;
    }
    rlmsg::sample_batch_t b{};
    b.requester = r.header.sender;
    b.request_id = r.request_id;
    b.obs_size = obs_size_;
    b.count = r.batch_size;
    b.num_values = obs_size_ * b.count;
    std::normal_distribution<float> normal;
    for (int i = 0; i < b.num_values; ++i) {
      b.obs.push_back(normal(rng_));
      b.next_obs.push_back(normal(rng_));
    }
    // The first bad_replies_ replies carry one action value too many.
    const int width = bad_replies_ > 0 ? action_width_ + 1 : action_width_;
    if (bad_replies_ > 0) --bad_replies_;
    b.action_width = width;
    b.num_action_values = b.count * width;
    std::uniform_real_distribution<float> torque(-2.0f, 2.0f);
    for (int i = 0; i < b.count; ++i) {
      for (int k = 0; k < width; ++k) {
        // CartPole: alternating indices; Pendulum: torques in [-2, 2].
        b.action.push_back(continuous_ ? torque(rng_) : static_cast<float>(i % 2));
      }
      b.reward.push_back(1.0f);
      b.discount.push_back(0.99f);
      b.index.push_back(i);
      b.weight.push_back(1.0f);
    }
    b.replay_size = 1000;
    b.total_inserts = 1234;
    bus_->Publish(channels::kSamples, &b, Port::kSamples);
  }

  // A batch of Catch-shaped pixel transitions (stack 2 of 10 x 5 frames); transition i is
  // reported as index 1000 * request_id + i.
  void ReplyPixels(const rlmsg::sample_request_t& r) {
    rlmsg::sample_batch_t b{};
    b.requester = r.header.sender;
    b.request_id = r.request_id;
    b.height = 10;
    b.width = 5;
    b.stack = 2;
    b.count = r.batch_size;
    b.num_bytes = 100 * b.count;
    std::uniform_int_distribution<int> byte(0, 255);
    for (int i = 0; i < b.num_bytes; ++i) {
      b.obs_pixels.push_back(static_cast<uint8_t>(byte(rng_)));
      b.next_obs_pixels.push_back(static_cast<uint8_t>(byte(rng_)));
    }
    b.action_width = 1;
    b.num_action_values = b.count;
    for (int i = 0; i < b.count; ++i) {
      b.action.push_back(static_cast<float>(i % 3));
      b.reward.push_back(i % 2 == 0 ? 1.0f : -1.0f);
      b.discount.push_back(0.0f);
      b.index.push_back(1000 * r.request_id + i);
      b.weight.push_back(0.5f);
    }
    b.replay_size = 1000;
    b.total_inserts = 4321;
    bus_->Publish(channels::kSamples, &b, Port::kSamples);
  }

  bool pixels_ = false;
  int obs_size_ = 4;
  int action_width_ = 1;
  int bad_replies_ = 0;
  bool continuous_ = false;
  std::unique_ptr<Bus> bus_;
  std::mt19937 rng_{1};
  bool dropped_first_ = false;
  bool retried_ = false;
  std::vector<rlmsg::sample_request_t> held_;
  int requests_seen_ = 0;
  std::vector<std::string> announced_;
  std::set<int64_t> versions_;
  std::map<int64_t, std::vector<float>> weights_;  // RecordWeights()
};

TEST_F(LearnerTest, TrainsBroadcastsWeightsAndWritesLoadableCheckpoints) {
  LearnerConfig c = ShortRun(32, 30, 10);
  c.weights_every = 10;
  Learner learner(c, bus_.get());
  learner.Run();
  bus_->Handle(0);
  EXPECT_EQ(learner.updates(), 30);
  // The lost request was sent again, with the same id.
  EXPECT_TRUE(retried_);
  EXPECT_GE(requests_seen_, 31);
  // Version 0 (the initial network) and every tenth update.
  EXPECT_TRUE(versions_.count(0));
  EXPECT_TRUE(versions_.count(10));
  EXPECT_TRUE(versions_.count(20));
  // Checkpoints at 10, 20, 30 and a last one when the run ends.
  ASSERT_EQ(announced_.size(), 4U);
  const nn::Checkpoint ckpt = nn::LoadCheckpoint(announced_[1]);
  EXPECT_EQ(ckpt.meta.update, 20);
  EXPECT_EQ(ckpt.meta.env_steps, 1234);
  EXPECT_EQ(ckpt.meta.run_id, 9U);
  EXPECT_EQ(ckpt.architecture, learner.algorithm().policy().Architecture());
  // The last checkpoint holds the final parameters.
  std::vector<float> flat;
  learner.algorithm().policy().GetFlat(&flat);
  EXPECT_EQ(nn::LoadCheckpoint(announced_.back()).params, flat);
}

TEST_F(LearnerTest, TrainsOnPixelBatchesAndSendsTheirTdErrorsAsPriorities) {
  pixels_ = true;
  std::vector<rlmsg::priority_update_t> updates;
  bus_->Subscribe<rlmsg::priority_update_t>(
      channels::kPriorities,
      [&updates](const rlmsg::priority_update_t& m) { updates.push_back(m); });
  LearnerConfig c = ShortRun(16, 20, 100);
  c.env_id = "Catch-v0+pixels(width=5,height=10,stack=2,max-pool=0)";
  c.Get<DqnConfig>().network = "conv2d(2,4,3,1,1,10,5),relu,flatten,linear(200,3)";
  // Random shifts need the frame size, which comes from the env's static spec.
  c.augment_shift = 2;
  c.prioritized = true;
  Learner learner(c, bus_.get());
  learner.Run();
  bus_->Handle(0);
  EXPECT_EQ(learner.updates(), 20);
  // One update per trained batch, naming the batch's transitions with their |TD errors|.
  ASSERT_EQ(updates.size(), 20U);
  for (const auto& u : updates) {
    ASSERT_EQ(u.count, 16);
    const int64_t request = u.index[0] / 1000;
    for (int i = 0; i < u.count; ++i) {
      EXPECT_EQ(u.index[static_cast<size_t>(i)], 1000 * request + i);
      EXPECT_GE(u.priority[static_cast<size_t>(i)], 0.0f);
    }
  }
  // Terminal transitions: the TD error is |reward - Q(s, a)|, so the last update's priorities
  // differ between the +1 and -1 rewards.
  EXPECT_NE(updates.back().priority[0], updates.back().priority[1]);
  const nn::Checkpoint ckpt = nn::LoadCheckpoint(announced_.back());
  EXPECT_EQ(ckpt.meta.env_steps, 4321);
}

// With two compute threads (--threads 2) the learner trains as with one, its convolution split
// over nn's pool (ThreadSanitizer runs this test: scripts/test.sh, preset tsan).
TEST_F(LearnerTest, TrainsOnTwoComputeThreads) {
  pixels_ = true;
  LearnerConfig c = ShortRun(256, 5, 100);
  c.env_id = "Catch-v0+pixels(width=5,height=10,stack=2,max-pool=0)";
  // 256 x 64 x 2 x 9 x 50 = 14.7M multiply-adds per convolution: enough to be split.
  c.Get<DqnConfig>().network = "conv2d(2,64,3,1,1,10,5),relu,flatten,linear(3200,3)";
  c.threads = 2;
  const int64_t sections = nn::internal::ParallelSections();
  {
    Learner learner(c, bus_.get());
    learner.Run();
    bus_->Handle(0);
    EXPECT_EQ(learner.updates(), 5);
  }
  EXPECT_GT(nn::internal::ParallelSections(), sections) << "nothing ran on two threads";
  nn::SetNumThreads(1);
}

TEST_F(LearnerTest, KeepsOnlyTheNewestCheckpointFiles) {
  LearnerConfig c = ShortRun(8, 50, 10);
  c.keep_checkpoints = 2;
  Learner learner(c, bus_.get());
  learner.Run();
  std::vector<std::string> left;
  for (const auto& e : fs::directory_iterator(dir_ / "checkpoints")) {
    left.push_back(e.path().filename().string());
  }
  std::sort(left.begin(), left.end());
  // The learner's state (for a restart) is kept beside them.
  EXPECT_EQ(left, (std::vector<std::string>{"ckpt-000000040.bin", "ckpt-000000050.bin",
                                            "learner-state.bin"}));
}

// A restarted or resumed learner counts the checkpoint files of its earlier lives towards
// keep_checkpoints (they go first), so they do not pile up; other files stay.
TEST_F(LearnerTest, KeepsOnlyTheNewestCheckpointFilesOfEveryLife) {
  LearnerConfig c = ShortRun(8, 60, 10);
  c.keep_checkpoints = 0;        // all: 10, 20, ..., 60
  Learner first(c, bus_.get());  // alive to the end: the bus keeps its handler
  first.Run();
  bus_->Handle(0);
  for (const char* name : {"ckpt-000000070.bin.tmp.77", "notes.txt", "ckpt-abc.bin"}) {
    std::ofstream(dir_ / "checkpoints" / name) << "x";
  }
  c.keep_checkpoints = 3;
  c.resume = true;
  c.max_updates = 80;
  Learner second(c, bus_.get());
  ASSERT_TRUE(second.resumed());
  second.Run();  // 70, 80
  std::vector<std::string> left;
  for (const auto& e : fs::directory_iterator(dir_ / "checkpoints")) {
    left.push_back(e.path().filename().string());
  }
  std::sort(left.begin(), left.end());
  // The temporary file of a write that a kill cut short is removed at start; files that are not
  // the learner's stay.
  EXPECT_EQ(left, (std::vector<std::string>{"ckpt-000000060.bin", "ckpt-000000070.bin",
                                            "ckpt-000000080.bin", "ckpt-abc.bin",
                                            "learner-state.bin", "notes.txt"}));
}

TEST(LearnerConfigTest, RefusesBadSettings) {
  LearnerConfig c;
  c.requests_in_flight = 0;
  EXPECT_THROW(c.Validate(), std::invalid_argument);
  c = LearnerConfig{};
  c.policy_average = -1;
  EXPECT_THROW(c.Validate(), std::invalid_argument);
  c = LearnerConfig{};
  c.learning_rate_decay_updates = -1;
  EXPECT_THROW(c.Validate(), std::invalid_argument);
  for (double end : {-0.1, 1.5, std::nan("")}) {
    c = LearnerConfig{};
    c.learning_rate_end = end;
    EXPECT_THROW(c.Validate(), std::invalid_argument) << end;
  }
}

TEST(LearnerConfigTest, LearningRatesFallLinearlyThenHold) {
  EXPECT_EQ(LearningRateScale(0, 0, 0.1), 1.0f);  // No decay.
  EXPECT_EQ(LearningRateScale(500, 0, 0.1), 1.0f);
  EXPECT_EQ(LearningRateScale(0, 10, 0.1), 1.0f);
  EXPECT_FLOAT_EQ(LearningRateScale(5, 10, 0.1), 0.55f);
  EXPECT_FLOAT_EQ(LearningRateScale(10, 10, 0.1), 0.1f);
  EXPECT_FLOAT_EQ(LearningRateScale(1000, 10, 0.1), 0.1f);
  EXPECT_FLOAT_EQ(LearningRateScale(3, 4, 0.0), 0.25f);
}

TEST_F(LearnerTest, RefusesRandomShiftsForAnEnvWithoutPixels) {
  LearnerConfig c;
  c.augment_shift = 4;
  c.out_dir = dir_.string();
  EXPECT_THROW(Learner(c, bus_.get()), std::invalid_argument);
}

// TD3 on Pendulum-v1: trains on replies of one-float torques and broadcasts and checkpoints its
// actor (3 inputs, 1 output in [-2, 2]), not a critic.
TEST_F(LearnerTest, TrainsTd3AndPublishesItsActor) {
  const LearnerConfig c = ShortTd3PendulumRun(16, 20, 10);
  Learner learner(c, bus_.get());
  learner.Run();
  bus_->Handle(0);
  EXPECT_EQ(learner.updates(), 20);
  EXPECT_EQ(learner.batches_refused(), 0);
  const nn::Checkpoint ckpt = nn::LoadCheckpoint(announced_.back());
  std::mt19937 rng(0);
  nn::Sequential actor = nn::BuildFromArchitecture(ckpt.architecture, &rng);
  EXPECT_EQ(actor.InputSize(), 3);
  EXPECT_EQ(actor.OutputSize(), 1);
  EXPECT_NE(ckpt.architecture.find("bounded(1,-2,2)"), std::string::npos) << ckpt.architecture;
}

// Replies whose actions are not the env's width are dropped and counted, never trained on; the
// learner goes on with the next ones.
TEST_F(LearnerTest, CountsAndDropsRepliesThatDoNotFitTheEnv) {
  bad_replies_ = 3;  // two action values where CartPole has one
  std::vector<rlmsg::stats_learner_t> stats;
  bus_->Subscribe<rlmsg::stats_learner_t>(
      channels::kStatsLearner, [&stats](const rlmsg::stats_learner_t& s) { stats.push_back(s); });
  LearnerConfig c = ShortRun(8, 5);
  Learner learner(c, bus_.get());
  learner.Run();
  bus_->Handle(0);
  EXPECT_EQ(learner.batches_refused(), 3);
  EXPECT_EQ(learner.updates(), 5);
  ASSERT_FALSE(stats.empty());
  EXPECT_EQ(stats.back().dropped_invalid, 3);
}

TEST(LearnerConfigTest, RefusesAlgorithmsThatDoNotFitTheEnv) {
  Bus bus(InProcessBusConfig(0, "learner"));
  LearnerConfig c;
  c.algorithm = "td3";  // CartPole-v1 is discrete
  const TempDir dir;
  c.out_dir = (dir / "run").string();
  EXPECT_THROW(Learner(c, &bus), std::invalid_argument);
  c.algorithm = "dqn";
  c.env_id = "Pendulum-v1";  // continuous
  EXPECT_THROW(Learner(c, &bus), std::invalid_argument);
  c.algorithm = "sac";
  EXPECT_THROW(c.Validate(), std::invalid_argument);
}

// A restarted learner with --resume continues from the state written with its last checkpoint:
// the update count, env steps and weight versions carry on, and nothing goes back. Both learners
// live to the end of the test: the bus keeps their subscriptions.
void ExpectResumes(LearnerConfig c, Bus* bus, std::set<int64_t>* versions,
                   std::vector<std::string>* announced) {
  std::vector<float> saved_policy;
  Learner first(c, bus);
  EXPECT_FALSE(first.resumed());
  first.Run();
  first.algorithm().policy().GetFlat(&saved_policy);
  bus->Handle(0);
  versions->clear();
  c.resume = true;
  c.max_updates = 45;
  Learner second(c, bus);
  ASSERT_TRUE(second.resumed());
  EXPECT_EQ(second.updates(), 30);
  std::vector<float> policy;
  second.algorithm().policy().GetFlat(&policy);
  EXPECT_EQ(policy, saved_policy);
  second.Run();
  bus->Handle(0);
  EXPECT_EQ(second.updates(), 45);
  ASSERT_FALSE(versions->empty());
  EXPECT_EQ(*versions->begin(), 30) << "the first broadcast of the resumed learner";
  const nn::Checkpoint last = nn::LoadCheckpoint(announced->back());
  EXPECT_EQ(last.meta.update, 45);
  EXPECT_EQ(last.meta.env_steps, 1234);
}

TEST_F(LearnerTest, DqnResumesFromItsSavedStateAndNeverGoesBack) {
  ExpectResumes(ShortRun(16, 30, 10), bus_.get(), &versions_, &announced_);
}

TEST_F(LearnerTest, Td3ResumesFromItsSavedStateAndNeverGoesBack) {
  const LearnerConfig c = ShortTd3PendulumRun(16, 30, 10);
  ExpectResumes(c, bus_.get(), &versions_, &announced_);
}

// precision = bf16 reaches the networks, the checkpoint's note and the state: a resume keeps it
// and one in another precision is refused, naming both.
TEST_F(LearnerTest, Bf16ResumesInBf16AndRefusesAnotherPrecision) {
  LearnerConfig c = ShortRun(16, 30, 10);
  c.precision = "bf16";
  Learner probe(c, bus_.get());  // alive to the end: the bus keeps its handler
  EXPECT_EQ(probe.algorithm().policy().precision(), nn::Precision::kBf16);
  ExpectResumes(c, bus_.get(), &versions_, &announced_);
  EXPECT_NE(nn::LoadCheckpoint(announced_.back()).meta.note.find("precision = bf16"),
            std::string::npos);
  LearnerConfig fp32 = c;
  fp32.precision = "fp32";
  fp32.resume = true;
  try {
    Learner other(fp32, bus_.get());
    ADD_FAILURE() << "a bf16 state was resumed in fp32";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("precision bf16, this run's is fp32"), std::string::npos)
        << e.what();
  }
  c.precision = "fp16";
  EXPECT_THROW(c.Validate(), std::invalid_argument);
}

// precision = auto is bf16 on a kernel path with native bf16 products and fp32 on one without
// (each path this CPU runs), and a resume keeps the precision the saved state was trained in
// whatever the path: a bf16 state resumes in bf16 on the fp32-only path, not refused.
TEST_F(LearnerTest, AutoPrecisionFollowsTheCpuAndAResumeKeepsTheSavedOne) {
  LearnerConfig c = ShortRun(16, 30, 10);
  c.precision = "auto";
  EXPECT_NO_THROW(c.Validate());
  std::vector<std::unique_ptr<Learner>> alive;  // alive to the end: the bus keeps their handlers
  for (const std::string& path : nn::RunnableKernelPaths()) {
    nn::SetKernelPath(path);
    alive.push_back(std::make_unique<Learner>(c, bus_.get()));
    const bool native = nn::NativeBf16();
    EXPECT_EQ(alive.back()->precision(), native ? "bf16" : "fp32") << path;
    EXPECT_EQ(alive.back()->algorithm().policy().precision(),
              native ? nn::Precision::kBf16 : nn::Precision::kFp32)
        << path;
  }
  nn::SetKernelPath("auto");
  LearnerConfig bf16 = c;
  bf16.precision = "bf16";
  alive.push_back(std::make_unique<Learner>(bf16, bus_.get()));
  alive.back()->Run();                                  // writes a bf16 state
  nn::SetKernelPath(nn::RunnableKernelPaths().back());  // the slowest: bf16 emulated
  ASSERT_FALSE(nn::NativeBf16());
  c.resume = true;
  alive.push_back(std::make_unique<Learner>(c, bus_.get()));
  nn::SetKernelPath("auto");
  EXPECT_TRUE(alive.back()->resumed());
  EXPECT_EQ(alive.back()->precision(), "bf16");
  EXPECT_EQ(alive.back()->updates(), 30);
}

TEST_F(LearnerTest, RefusesAStateOfAnotherRunOrATornOne) {
  Learner first(ShortRun(8, 10, 10), bus_.get());  // alive to the end: the bus keeps its handler
  first.Run();
  const std::string state = (dir_ / "checkpoints" / "learner-state.bin").string();
  ASSERT_TRUE(fs::exists(state));
  // Another algorithm (the state's kind) and another env (same algorithm).
  LearnerConfig td3 = ShortRun(8, 10, 10);
  td3.env_id = "Pendulum-v1";
  td3.algorithm = "td3";
  td3.resume = true;
  EXPECT_THROW(Learner(td3, bus_.get()), std::runtime_error);
  LearnerConfig lunar = ShortRun(8, 10, 10);
  lunar.env_id = "LunarLander-v3";
  lunar.resume = true;
  EXPECT_THROW(Learner(lunar, bus_.get()), std::runtime_error);
  // A torn file.
  fs::resize_file(state, fs::file_size(state) / 2);
  LearnerConfig same = ShortRun(8, 10, 10);
  same.resume = true;
  try {
    Learner torn(same, bus_.get());
    ADD_FAILURE() << "a torn state was loaded";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("learner-state.bin"), std::string::npos) << e.what();
  }
  // Without --resume the state is ignored and the learner starts afresh.
  same.resume = false;
  Learner fresh(same, bus_.get());
  EXPECT_FALSE(fresh.resumed());
  EXPECT_EQ(fresh.updates(), 0);
}

// A restarted learner loads, with its state, the last reply it had taken from each replay:
// replies recorded before its last checkpoint and played back to it are dropped as replayed,
// inside the freshness window too; later ones pass the bus (and match no request of its).
TEST_F(LearnerTest, AResumedLearnerRefusesRecordedRepliesOlderThanItsState) {
  std::vector<std::vector<uint8_t>> recorded;  // every reply, as it went over the bus
  bus_->Subscribe<rlmsg::sample_batch_t>(
      channels::kSamples,
      [&recorded](const rlmsg::sample_batch_t& m) {
        std::vector<uint8_t> bytes(static_cast<size_t>(m.getEncodedSize()));
        m.encode(bytes.data(), 0, static_cast<int>(bytes.size()));
        recorded.push_back(std::move(bytes));
      },
      Port::kSamples);
  LearnerConfig c = ShortRun(16, 30, 10);
  Learner first(c, bus_.get());  // alive to the end: the bus keeps its handler
  first.Run();                   // its last checkpoint (and state) when it stops
  const size_t before_state = recorded.size();
  bus_->Handle(0);  // replies to requests still in flight
  ASSERT_GT(before_state, 0U);
  Bus restarted(InProcessBusConfig(9, "learner"));  // the new process's bus
  c.resume = true;
  Learner second(c, &restarted);
  ASSERT_TRUE(second.resumed());
  for (const auto& bytes : recorded) {
    restarted.Deliver(channels::kSamples, bytes.data(), bytes.size(), WallMicros());
  }
  EXPECT_EQ(restarted.counters().replayed, static_cast<int64_t>(before_state));
  EXPECT_EQ(restarted.counters().received, static_cast<int64_t>(recorded.size() - before_state));
}

// With policy_average, checkpoints hold the average of the policies after each update (the
// weights broadcast with every update here, the current ones), and say so; a resumed learner
// continues the average from its state.
TEST_F(LearnerTest, CheckpointsHoldThePolicysAverageAndAResumeContinuesIt) {
  std::map<int64_t, std::vector<float>>& broadcast = RecordWeights();
  LearnerConfig c = ShortRun(16, 30, 10);
  c.weights_every = 1;
  c.policy_average = 5;
  Learner first(c, bus_.get());  // alive to the end: the bus keeps its handler
  first.Run();
  bus_->Handle(0);
  // The average the checkpoints should hold: of every version broadcast up to `last`.
  ParameterAverage expected(5);
  int64_t added = 0;
  const auto average_up_to = [&](int64_t last) {
    while (added < last) {
      ++added;
      ASSERT_TRUE(broadcast.count(added)) << "version " << added;
      expected.Add(broadcast[added]);
    }
  };
  average_up_to(30);
  const nn::Checkpoint last = nn::LoadCheckpoint(announced_.back());
  EXPECT_EQ(last.meta.update, 30);
  EXPECT_EQ(last.params, expected.values());
  EXPECT_NE(last.params, broadcast[30]);
  EXPECT_NE(last.meta.note.find("policy = the average of about 5 updates"), std::string::npos)
      << last.meta.note;

  c.resume = true;
  c.max_updates = 35;
  Learner second(c, bus_.get());
  ASSERT_TRUE(second.resumed());
  second.Run();
  bus_->Handle(0);
  average_up_to(35);
  const nn::Checkpoint resumed = nn::LoadCheckpoint(announced_.back());
  EXPECT_EQ(resumed.meta.update, 35);
  EXPECT_EQ(resumed.params, expected.values());
}

// With a learning-rate decay to 0 over 10 updates, the 10th update is the last that moves the
// policy (the weights broadcast after every update show it), the checkpoints say where the
// schedule stands, and a resumed learner stays on it (its updates count from the state).
TEST_F(LearnerTest, LearningRatesDecayWithTheUpdatesAndAcrossAResume) {
  std::map<int64_t, std::vector<float>>& broadcast = RecordWeights();
  LearnerConfig c = ShortRun(16, 20, 5);
  c.weights_every = 1;
  c.learning_rate_decay_updates = 10;
  c.learning_rate_end = 0;
  Learner first(c, bus_.get());
  first.Run();
  bus_->Handle(0);
  for (int64_t v = 1; v <= 10; ++v) {
    ASSERT_TRUE(broadcast.count(v - 1) && broadcast.count(v)) << v;
    EXPECT_NE(broadcast[v], broadcast[v - 1]) << "update " << v << " should move the policy";
  }
  for (int64_t v = 11; v <= 20; ++v) {
    ASSERT_TRUE(broadcast.count(v)) << v;
    EXPECT_EQ(broadcast[v], broadcast[10]) << "update " << v << " should not";
  }
  const nn::Checkpoint at5 = nn::LoadCheckpoint(announced_[0]);
  ASSERT_EQ(at5.meta.update, 5);
  EXPECT_NE(at5.meta.note.find("learning rates = 0.5 of their start"), std::string::npos)
      << at5.meta.note;

  c.resume = true;
  c.max_updates = 25;
  Learner second(c, bus_.get());
  ASSERT_TRUE(second.resumed());
  second.Run();
  bus_->Handle(0);
  ASSERT_TRUE(broadcast.count(25));
  EXPECT_EQ(broadcast[25], broadcast[10]);
  // Without the decay, the same resumed learner moves on.
  c.learning_rate_decay_updates = 0;
  c.max_updates = 30;
  Learner third(c, bus_.get());
  ASSERT_TRUE(third.resumed());
  third.Run();
  bus_->Handle(0);
  ASSERT_TRUE(broadcast.count(30));
  EXPECT_NE(broadcast[30], broadcast[10]);
}

}  // namespace
}  // namespace rl::learner
