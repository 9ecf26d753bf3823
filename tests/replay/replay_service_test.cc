#include "replay/replay_service.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <memory>
#include <set>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "common/channels.h"
#include "common/clock.h"
#include "common/lcm_bus.h"
#include "common/message_examples.h"

namespace rl::replay {
namespace {

constexpr int64_t kRunId = 42;

BusConfig MemqConfig() { return InProcessBusConfig(kRunId, "replay"); }

ReplayServiceOptions Options(double spi, int64_t min_size, double error_buffer) {
  ReplayServiceOptions o;
  o.table.capacity = 1000;
  o.limiter.samples_per_insert = spi;
  o.limiter.min_size_to_sample = min_size;
  o.limiter.error_buffer = error_buffer;
  return o;
}

// Transition v has obs {v, v + 0.5, ...}, next_obs obs + 1000, action v % 2, reward v / 4,
// no priority given.
rlmsg::transition_batch_t MakeBatch(int first, int count, int obs_size) {
  rlmsg::transition_batch_t m = examples::FlatTransitions(first, count, obs_size);
  for (float& r : m.reward) r /= 4.0f;
  m.priority.assign(m.priority.size(), 0.0f);
  return m;
}

// One bus shared by the service and the test (memq delivers within one LCM instance). The test
// publishes as other senders by encoding the header itself.
class ReplayServiceTest : public ::testing::Test {
 protected:
  ReplayServiceTest() : bus_(MemqConfig()) {
    bus_.Subscribe<rlmsg::sample_batch_t>(
        channels::kSamples, [this](const rlmsg::sample_batch_t& m) { replies_.push_back(m); },
        Port::kSamples);
    bus_.Subscribe<rlmsg::flow_control_t>(
        channels::kFlow, [this](const rlmsg::flow_control_t& m) { flows_.push_back(m); });
    bus_.Subscribe<rlmsg::stats_replay_t>(
        channels::kStatsReplay, [this](const rlmsg::stats_replay_t& m) { stats_.push_back(m); });
  }

  void Start(const ReplayServiceOptions& options) {
    service_ = std::make_unique<ReplayService>(&bus_, options);
  }

  template <class Msg>
  void PublishAs(const std::string& channel, Msg m, const std::string& sender,
                 int64_t run_id = kRunId) {
    m.header.run_id = run_id;
    m.header.sender = sender;
    m.header.seq = next_seq_[{channel, sender}]++;
    m.header.utime = WallMicros();
    std::vector<uint8_t> bytes(static_cast<size_t>(m.getEncodedSize()));
    ASSERT_EQ(m.encode(bytes.data(), 0, static_cast<int>(bytes.size())),
              static_cast<int>(bytes.size()));
    ASSERT_TRUE(bus_.PublishRaw(channel, bytes.data(), bytes.size()));
  }

  void SendTransitions(int first, int count, int obs_size = 4) {
    PublishAs(channels::kTransitions, MakeBatch(first, count, obs_size), "actor-0");
  }

  void SendRequest(int64_t request_id, int batch_size) {
    rlmsg::sample_request_t r{};
    r.request_id = request_id;
    r.batch_size = batch_size;
    PublishAs(channels::kSampleRequest, r, "learner-0");
  }

  // Delivers what was published, lets the service answer, and delivers its replies.
  void Pump() {
    bus_.Handle(0);
    service_->Serve();
    bus_.Handle(0);
  }

  // Lets the service publish what is due at time `now` (seconds) and delivers it.
  void TickAndDeliver(double now) {
    service_->Tick(now);
    bus_.Handle(0);
  }

  // The request ids of the replies so far, in order.
  std::vector<int64_t> ReplyIds() const {
    std::vector<int64_t> ids;
    for (const rlmsg::sample_batch_t& r : replies_) ids.push_back(r.request_id);
    return ids;
  }

  // Checks that `r` is the replay's answer to learner-0's request `request_id` of `count`.
  static void ExpectReplyTo(const rlmsg::sample_batch_t& r, int64_t request_id, int count) {
    EXPECT_EQ(r.header.sender, "replay");
    EXPECT_EQ(r.requester, "learner-0");
    EXPECT_EQ(r.request_id, request_id);
    EXPECT_EQ(r.count, count);
  }

  Bus bus_;
  std::unique_ptr<ReplayService> service_;
  std::map<std::pair<std::string, std::string>, int64_t> next_seq_;
  std::vector<rlmsg::sample_batch_t> replies_;
  std::vector<rlmsg::flow_control_t> flows_;
  std::vector<rlmsg::stats_replay_t> stats_;
};

TEST_F(ReplayServiceTest, RefusesBadOptions) {
  ReplayServiceOptions o = Options(8, 100, 200);
  o.max_pending_requests = 0;
  EXPECT_THROW(Start(o), std::invalid_argument);
  o = Options(8, 100, 200);
  o.flow_hz = 0;
  EXPECT_THROW(Start(o), std::invalid_argument);
  o = Options(8, 100, 2);  // error buffer below samples_per_insert
  EXPECT_THROW(Start(o), std::invalid_argument);
}

TEST_F(ReplayServiceTest, StoresIncomingTransitions) {
  Start(Options(8, 100, 200));
  SendTransitions(0, 10);
  SendTransitions(10, 15);
  Pump();
  EXPECT_EQ(service_->table().size(), 25);
  EXPECT_EQ(service_->table().total_inserts(), 25);
  EXPECT_EQ(service_->limiter().inserts(), 25);
  EXPECT_EQ(bus_.counters().lost, 0);
}

TEST_F(ReplayServiceTest, HoldsARequestUntilMinSizeThenAnswersIt) {
  Start(Options(8, 50, 400));
  SendTransitions(0, 20);
  SendRequest(7, 16);
  Pump();
  EXPECT_TRUE(replies_.empty());
  EXPECT_EQ(service_->pending_requests(), 1);

  SendTransitions(20, 30);
  Pump();
  ASSERT_EQ(replies_.size(), 1U);
  EXPECT_EQ(service_->pending_requests(), 0);
  const rlmsg::sample_batch_t& r = replies_[0];
  ExpectReplyTo(r, 7, 16);
  EXPECT_EQ(r.obs_size, 4);
  EXPECT_EQ(r.num_values, 64);
  EXPECT_EQ(r.replay_size, 50);
  EXPECT_EQ(r.total_inserts, 50);
  // Every transition is one that was inserted, whole and in the right place.
  for (size_t i = 0; i < 16; ++i) {
    const float v = r.obs[i * 4];
    ASSERT_GE(v, 0.0f);
    ASSERT_LT(v, 50.0f);
    ASSERT_EQ(v, std::floor(v));
    for (size_t j = 0; j < 4; ++j) {
      EXPECT_EQ(r.obs[i * 4 + j], v + 0.5f * static_cast<float>(j));
      EXPECT_EQ(r.next_obs[i * 4 + j], v + 0.5f * static_cast<float>(j) + 1000.0f);
    }
    EXPECT_EQ(r.action[i], static_cast<float>(static_cast<int>(v) % 2));
    EXPECT_EQ(r.reward[i], v / 4.0f);
    EXPECT_EQ(r.discount[i], 0.99f);
    EXPECT_EQ(r.index[i], static_cast<int64_t>(v));
    EXPECT_EQ(r.weight[i], 1.0f);
  }
  EXPECT_EQ(service_->table().total_samples(), 16);
  EXPECT_EQ(service_->counters().requests_answered, 1);
}

TEST_F(ReplayServiceTest, HoldsARetriedRequestOnceAndAnswersItOnce) {
  Start(Options(8, 50, 400));
  SendRequest(7, 16);
  SendRequest(7, 16);  // the learner's retry after a timeout
  SendRequest(8, 16);
  Pump();
  EXPECT_EQ(service_->pending_requests(), 2);
  SendTransitions(0, 50);
  Pump();
  ASSERT_EQ(ReplyIds(), (std::vector<int64_t>{7, 8}));
}

TEST_F(ReplayServiceTest, AnswersSeveralRequestsInOrderAsTheLimiterAllows) {
  // SPI 1, min 10, error buffer 10: right after the warm-up (diff 10), 10 samples are allowed.
  Start(Options(1, 10, 10));
  SendTransitions(0, 10);
  SendRequest(1, 6);
  SendRequest(2, 6);
  SendRequest(3, 2);
  Pump();
  // The first fits; the second must wait (diff 4 - 6 < 0) and holds up the third.
  ASSERT_EQ(ReplyIds(), (std::vector<int64_t>{1}));
  EXPECT_EQ(service_->pending_requests(), 2);
  SendTransitions(10, 4);  // diff 8
  Pump();
  ASSERT_EQ(ReplyIds(), (std::vector<int64_t>{1, 2, 3}));
}

TEST_F(ReplayServiceTest, FlowControlPausesActorsThatRunAheadAndResumesThemAfterSamples) {
  // max_diff = 1 * 10 + 10 = 20: one more insert is refused once 20 transitions are in.
  Start(Options(1, 10, 10));
  EXPECT_TRUE(service_->insert_allowed());
  SendTransitions(0, 5);
  SendTransitions(5, 5);
  SendTransitions(10, 5);
  Pump();
  EXPECT_TRUE(flows_.empty()) << "no change yet, so no immediate flow message";
  SendTransitions(15, 5);
  Pump();
  ASSERT_EQ(flows_.size(), 1U);
  EXPECT_EQ(flows_[0].insert_allowed, 0);
  EXPECT_EQ(flows_[0].target_samples_per_insert, 1.0);
  EXPECT_EQ(flows_[0].error_buffer, 10.0);
  EXPECT_FALSE(service_->insert_allowed());

  // Transitions still in flight are stored all the same.
  SendTransitions(20, 2);
  Pump();
  EXPECT_EQ(service_->table().size(), 22);
  EXPECT_EQ(flows_.size(), 1U);

  // The learner catches up: diff 22 - 12 = 10, and 11 <= 20 allows inserts again.
  SendRequest(1, 12);
  Pump();
  ASSERT_EQ(replies_.size(), 1U);
  ASSERT_EQ(flows_.size(), 2U);
  EXPECT_EQ(flows_[1].insert_allowed, 1);
  EXPECT_TRUE(service_->insert_allowed());
  // The credit: (max_diff - diff) / SPI = 20 - 10 transitions, and what each actor has stored.
  EXPECT_EQ(flows_[0].insert_credit, 0);
  EXPECT_EQ(flows_[1].insert_credit, 10);
  EXPECT_EQ(flows_[1].actor_id, std::vector<int32_t>{0});
  EXPECT_EQ(flows_[1].actor_inserts, std::vector<int64_t>{22});

  // Samples that raise the credit by a quarter of its range (2 * 10 / 1 / 4 = 5) announce it.
  SendRequest(2, 4);  // credit 14: not yet
  Pump();
  EXPECT_EQ(flows_.size(), 2U);
  SendRequest(3, 1);  // credit 15
  Pump();
  ASSERT_EQ(flows_.size(), 3U);
  EXPECT_EQ(flows_[2].insert_credit, 15);
}

TEST_F(ReplayServiceTest, DropsForeignAndNonFiniteBatchesAndKeepsWorking) {
  Start(Options(1, 5, 10));
  PublishAs(channels::kTransitions, MakeBatch(0, 5, 4), "actor-9", /*run_id=*/kRunId + 1);
  rlmsg::transition_batch_t nan = MakeBatch(0, 5, 4);
  nan.obs[3] = std::numeric_limits<float>::quiet_NaN();
  PublishAs(channels::kTransitions, nan, "actor-0");
  Pump();
  EXPECT_EQ(service_->table().size(), 0);
  EXPECT_EQ(bus_.counters().foreign, 1);
  EXPECT_EQ(bus_.counters().invalid, 1);

  SendTransitions(0, 5);
  SendRequest(1, 3);
  Pump();
  EXPECT_EQ(service_->table().size(), 5);
  ASSERT_EQ(replies_.size(), 1U);
  TickAndDeliver(100.0);
  ASSERT_EQ(stats_.size(), 1U);
  EXPECT_EQ(stats_[0].dropped_foreign, 1);
  EXPECT_EQ(stats_[0].dropped_invalid, 1);
  EXPECT_EQ(stats_[0].size, 5);
}

TEST_F(ReplayServiceTest, RefusesABatchOfAnotherObsSizeAndCountsItAsInvalid) {
  Start(Options(1, 5, 10));
  SendTransitions(0, 5, /*obs_size=*/4);
  SendTransitions(5, 5, /*obs_size=*/3);
  SendTransitions(10, 5, /*obs_size=*/4);
  Pump();
  EXPECT_EQ(service_->table().size(), 10);
  EXPECT_EQ(service_->counters().batches_refused, 1);
  // The limiter counts only what was stored.
  EXPECT_EQ(service_->limiter().inserts(), 10);
  TickAndDeliver(100.0);
  ASSERT_EQ(stats_.size(), 1U);
  EXPECT_EQ(stats_[0].dropped_invalid, 1);
}

TEST_F(ReplayServiceTest, DropsTheOldestRequestWhenTheQueueIsFull) {
  ReplayServiceOptions o = Options(0, 10, 0);  // no ratio: every request is served once warm
  o.max_pending_requests = 4;
  Start(o);
  for (int64_t id = 0; id < 6; ++id) SendRequest(id, 2);
  Pump();
  EXPECT_EQ(service_->pending_requests(), 4);
  EXPECT_EQ(service_->counters().requests_dropped, 2);
  SendTransitions(0, 10);
  Pump();
  ASSERT_EQ(ReplyIds(), (std::vector<int64_t>{2, 3, 4, 5}));
}

TEST_F(ReplayServiceTest, RefusesRequestsThatCouldNeverBeAnswered) {
  // max_sample_batch = 2 * 10 - 1 = 19.
  ReplayServiceOptions o = Options(1, 5, 10);
  o.max_reply_bytes = 1024;
  Start(o);
  SendRequest(1, 20);
  SendRequest(2, 19);  // allowed by the limiter, but its reply (~1.2 KB) exceeds 1024 bytes
  Pump();
  EXPECT_EQ(service_->counters().requests_refused, 1);
  EXPECT_EQ(service_->pending_requests(), 1);
  SendTransitions(0, 5);
  Pump();
  EXPECT_TRUE(replies_.empty());
  EXPECT_EQ(service_->counters().requests_refused, 2);
  EXPECT_EQ(service_->pending_requests(), 0);
  // A small one still goes through.
  SendRequest(3, 4);
  Pump();
  ASSERT_EQ(ReplyIds(), (std::vector<int64_t>{3}));
}

TEST_F(ReplayServiceTest, TickPublishesFlowAndStatsAtTheirRates) {
  ReplayServiceOptions o = Options(8, 100, 200);
  o.flow_hz = 20;  // every 0.05 s
  o.stats_hz = 4;  // every 0.25 s
  Start(o);
  SendTransitions(0, 8);
  Pump();
  TickAndDeliver(10.0);
  EXPECT_EQ(flows_.size(), 1U);
  EXPECT_EQ(stats_.size(), 1U);
  TickAndDeliver(10.01);
  EXPECT_EQ(flows_.size(), 1U);
  EXPECT_EQ(stats_.size(), 1U);
  TickAndDeliver(10.06);
  EXPECT_EQ(flows_.size(), 2U);
  EXPECT_EQ(stats_.size(), 1U);
  SendTransitions(8, 12);
  Pump();
  TickAndDeliver(10.5);
  EXPECT_EQ(flows_.size(), 3U);
  ASSERT_EQ(stats_.size(), 2U);

  const rlmsg::stats_replay_t& s = stats_[1];
  EXPECT_EQ(s.header.sender, "replay");
  EXPECT_EQ(s.size, 20);
  EXPECT_EQ(s.capacity, 1000);
  EXPECT_EQ(s.total_inserts, 20);
  EXPECT_EQ(s.total_samples, 0);
  EXPECT_DOUBLE_EQ(s.inserts_per_second, 12 / 0.5);
  EXPECT_EQ(s.samples_per_second, 0.0);
  EXPECT_EQ(s.insert_allowed, 1);
  EXPECT_EQ(s.pending_requests, 0);
  EXPECT_EQ(flows_.back().insert_allowed, 1);
  EXPECT_EQ(flows_.back().target_samples_per_insert, 8.0);
}

// Pixel transitions of one actor: frames 0 .. count (2 x 2 bytes, every byte of frame f equal
// to f), transition t with stack 2 naming frames {t - 1, t} (frame 0 repeated for t = 0) and
// next stack {t, t + 1}, action t % 3.
rlmsg::transition_batch_t MakePixelBatch(int count) {
  return examples::PixelTransitions(0, count, 2, 2);
}

TEST_F(ReplayServiceTest, StoresPixelTransitionsAndAnswersWithRebuiltStacks) {
  const std::vector<rlmsg::sample_batch_t>& replies = replies_;
  Start(Options(8, 10, 200));
  PublishAs(channels::kTransitions, MakePixelBatch(20), "actor-0");
  SendRequest(1, 16);
  Pump();
  EXPECT_EQ(service_->size(), 20);
  ASSERT_EQ(replies.size(), 1U);
  const rlmsg::sample_batch_t& r = replies[0];
  ExpectReplyTo(r, 1, 16);
  EXPECT_EQ(r.stack, 2);
  EXPECT_EQ(r.obs_size, 0);
  EXPECT_TRUE(r.obs.empty());
  EXPECT_EQ(r.num_bytes, 16 * 8);
  for (int i = 0; i < r.count; ++i) {
    // The reward tells which transition was drawn; its stacks hold the frames it named.
    const int t = static_cast<int>(r.reward[static_cast<size_t>(i)]);
    EXPECT_EQ(r.action[static_cast<size_t>(i)], static_cast<float>(t % 3));
    for (int b = 0; b < 4; ++b) {
      EXPECT_EQ(r.obs_pixels[static_cast<size_t>(8 * i + b)], std::max(t - 1, 0));
      EXPECT_EQ(r.obs_pixels[static_cast<size_t>(8 * i + 4 + b)], t);
      EXPECT_EQ(r.next_obs_pixels[static_cast<size_t>(8 * i + b)], t);
      EXPECT_EQ(r.next_obs_pixels[static_cast<size_t>(8 * i + 4 + b)], t + 1);
    }
    EXPECT_EQ(r.weight[static_cast<size_t>(i)], 1.0f);  // uniform sampling
  }
  // A flat batch in a pixel run is refused and counted.
  SendTransitions(0, 5);
  Pump();
  EXPECT_EQ(service_->counters().batches_refused, 1);
  EXPECT_EQ(service_->size(), 20);
}

// The env's spec fixes the table at the start: a first batch of the other kind, or of another
// frame geometry, is refused, not taken as the run's kind.
TEST_F(ReplayServiceTest, ThePixelTableOfTheEnvsKindRefusesAFirstFlatBatchOrOtherGeometry) {
  ReplayServiceOptions o = Options(8, 10, 200);
  o.kind = TableKind::kPixels;
  o.frames = {0, 2, 2, 2};
  Start(o);
  EXPECT_EQ(service_->table().kind(), TableKind::kPixels);
  SendTransitions(0, 5);
  Pump();
  EXPECT_EQ(service_->counters().batches_refused, 1);
  // Frames of 4 x 1 pixels: the same bytes, another geometry.
  rlmsg::transition_batch_t tall = MakePixelBatch(5);
  tall.height = 4;
  tall.width = 1;
  PublishAs(channels::kTransitions, tall, "actor-0");
  Pump();
  EXPECT_EQ(service_->counters().batches_refused, 2);
  PublishAs(channels::kTransitions, MakePixelBatch(20), "actor-0");
  Pump();
  EXPECT_EQ(service_->size(), 20);
  EXPECT_EQ(service_->table().kind(), TableKind::kPixels);
}

TEST_F(ReplayServiceTest, TheFlatTableOfTheEnvsKindRefusesAFirstPixelBatch) {
  ReplayServiceOptions flat = Options(8, 10, 200);
  flat.kind = TableKind::kFlat;
  Start(flat);
  PublishAs(channels::kTransitions, MakePixelBatch(20), "actor-0");
  Pump();
  EXPECT_EQ(service_->counters().batches_refused, 1);
  EXPECT_EQ(service_->table().kind(), TableKind::kFlat);
  SendTransitions(0, 5);
  Pump();
  EXPECT_EQ(service_->size(), 5);
}

// Continuous actions: three floats per transition go in and come back whole; a batch of another
// width, or with an action the env's check refuses, is refused and counted, and nothing of it
// is stored.
TEST_F(ReplayServiceTest, StoresActionVectorsAndRefusesBatchesWithBadActions) {
  ReplayServiceOptions o = Options(0, 1, 1000);
  o.table.action_width = 3;
  o.check_action = [](std::span<const float> a) -> const char* {
    return a[1] < 0.0f || a[1] > 1.0f ? "gas outside [0, 1]" : nullptr;
  };
  Start(o);
  auto batch = [](int first, int count, float gas) {
    rlmsg::transition_batch_t m = MakeBatch(first, count, 4);
    m.action_width = 3;
    m.num_action_values = 3 * count;
    m.action.clear();
    for (int v = first; v < first + count; ++v) {
      m.action.insert(m.action.end(), {-static_cast<float>(v) / 100, gas, 0.25f});
    }
    return m;
  };
  PublishAs(channels::kTransitions, batch(0, 10, 0.5f), "actor-0");
  PublishAs(channels::kTransitions, batch(10, 5, 1.5f), "actor-0");  // one bad value: all refused
  SendTransitions(20, 5);                                            // width 1
  Pump();
  EXPECT_EQ(service_->size(), 10);
  EXPECT_EQ(service_->counters().batches_refused, 2);
  SendRequest(1, 32);
  Pump();
  ASSERT_EQ(replies_.size(), 1U);
  const rlmsg::sample_batch_t& r = replies_[0];
  ExpectReplyTo(r, 1, 32);
  EXPECT_EQ(r.action_width, 3);
  ASSERT_EQ(r.action.size(), 96U);
  for (size_t i = 0; i < 32; ++i) {
    const float v = r.obs[i * 4];
    EXPECT_EQ(r.action[3 * i], -v / 100);
    EXPECT_EQ(r.action[3 * i + 1], 0.5f);
    EXPECT_EQ(r.action[3 * i + 2], 0.25f);
  }
  TickAndDeliver(1.0);
  ASSERT_FALSE(stats_.empty());
  EXPECT_GE(stats_.back().dropped_invalid, 2);
}

TEST_F(ReplayServiceTest, PrioritizedSamplingFollowsThePrioritiesTheLearnerSends) {
  ReplayServiceOptions o = Options(0, 10, 100000);
  o.prioritized = true;
  o.alpha = 1.0;
  o.beta = 0.5;
  Start(o);
  SendTransitions(0, 10);
  Pump();
  // Transition 3 gets almost all the mass; the others nearly none.
  rlmsg::priority_update_t u{};
  u.count = 10;
  for (int i = 0; i < 10; ++i) {
    u.index.push_back(i);
    u.priority.push_back(i == 3 ? 100.0f : 0.01f);
  }
  PublishAs(channels::kPriorities, u, "learner-0");
  // An update for a transition that does not exist is skipped and counted.
  rlmsg::priority_update_t stale{};
  stale.count = 1;
  stale.index = {12345};
  stale.priority = {5.0f};
  PublishAs(channels::kPriorities, stale, "learner-0");
  SendRequest(1, 200);
  Pump();
  EXPECT_EQ(service_->counters().priorities_applied, 10);
  EXPECT_EQ(service_->counters().priorities_stale, 1);
  ASSERT_EQ(replies_.size(), 1U);
  int threes = 0;
  for (int i = 0; i < 200; ++i) {
    const bool three = replies_[0].reward[static_cast<size_t>(i)] == 3.0f / 4.0f;
    threes += three;
    // Weights (N P(i))^-beta / max: 1 for the rarest transitions, far below for transition 3.
    if (three) {
      EXPECT_LT(replies_[0].weight[static_cast<size_t>(i)], 0.05f);
    } else {
      EXPECT_NEAR(replies_[0].weight[static_cast<size_t>(i)], 1.0f, 1e-4f);
    }
  }
  // P(3) = 100 / (100 + 9 * 0.01) = 0.9991: nearly every draw.
  EXPECT_GE(threes, 190);
  TickAndDeliver(1.0);
  ASSERT_FALSE(stats_.empty());
  EXPECT_EQ(stats_.back().prioritized, 1);
  EXPECT_DOUBLE_EQ(stats_.back().beta, 0.5);
  EXPECT_EQ(stats_.back().priorities_applied, 10);
  EXPECT_GT(stats_.back().memory_bytes, 0);
}

TEST_F(ReplayServiceTest, RunServesUntilAskedToStop) {
  Start(Options(8, 10, 200));
  SendTransitions(0, 10);
  SendRequest(5, 8);
  int rounds = 0;
  service_->Run([&] { return !replies_.empty() || ++rounds > 500; });
  ASSERT_EQ(ReplyIds(), (std::vector<int64_t>{5}));
  // Run leaves a last flow and stats message behind.
  bus_.Handle(0);
  ASSERT_FALSE(flows_.empty());
  ASSERT_FALSE(stats_.empty());
  EXPECT_EQ(stats_.back().total_samples, 8);
}

// Actors that stop with the replay send their last steps as they go: a replay asked to stop
// still stores what arrives (until it has been quiet a while), so its last snapshot has them.
TEST_F(ReplayServiceTest, RunStoresWhatArrivesAsItStops) {
  Start(Options(8, 10, 200));
  SendTransitions(0, 10);
  service_->Run([] { return true; });
  EXPECT_EQ(service_->total_inserts(), 10);
}

// Actor ids at or above max_actors are refused and counted: a forged id cannot grow the
// per-actor counts that every flow message and snapshot carries.
TEST_F(ReplayServiceTest, RefusesActorIdsFromMaxActorsOn) {
  ReplayServiceOptions o = Options(8, 100, 200);
  o.max_actors = 4;
  Start(o);
  for (const int32_t id : {3, 4, std::numeric_limits<int32_t>::max()}) {
    rlmsg::transition_batch_t m = MakeBatch(0, 5, 4);
    m.actor_id = id;
    PublishAs(channels::kTransitions, m, "actor-" + std::to_string(id));
  }
  Pump();
  EXPECT_EQ(service_->total_inserts(), 5);
  EXPECT_EQ(service_->counters().batches_refused, 2);
  TickAndDeliver(MonoSeconds());
  ASSERT_FALSE(flows_.empty());
  EXPECT_EQ(flows_.back().actor_id, std::vector<int32_t>{3});
  o.max_actors = 0;
  EXPECT_THROW(o.Validate(), std::invalid_argument);
  o.max_actors = kMaxActorsLimit + 1;
  EXPECT_THROW(o.Validate(), std::invalid_argument);
}

}  // namespace
}  // namespace rl::replay
