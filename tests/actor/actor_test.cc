#include "actor/actor.h"

#include <cmath>
#include <map>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "common/channels.h"
#include "envs/registry.h"
#include "learner/weights_publisher.h"
#include "nn/sequential.h"
#include "rlmsg/flow_control_t.hpp"
#include "rlmsg/stats_actor_t.hpp"

namespace rl::actor {
namespace {

BusConfig Memq() { return InProcessBusConfig(5, "actor-0"); }

class ActorTest : public ::testing::Test {
 protected:
  ActorTest() : bus_(Memq()) {
    config_.batch_size = 16;
    bus_.Subscribe<rlmsg::transition_batch_t>(
        channels::kTransitions,
        [this](const rlmsg::transition_batch_t& m) { batches_.push_back(m); });
    bus_.Subscribe<rlmsg::stats_actor_t>(
        channels::kStatsActor, [this](const rlmsg::stats_actor_t& s) { stats_.push_back(s); });
  }

  // Publishes `f` as the replay's flow message and delivers it.
  void SendFlow(rlmsg::flow_control_t* f) {
    bus_.Publish(channels::kFlow, f);
    bus_.Handle(0);
  }

  // Publishes version `version` of `net`'s parameters `flat` as the learner does (in chunks) and
  // delivers them.
  void SendWeights(int64_t version, const nn::Sequential& net, const std::vector<float>& flat) {
    for (auto& c : learner::MakeWeightChunks(version, net.Architecture(), flat)) {
      bus_.Publish(channels::kWeights, &c, Port::kBulk);
    }
    bus_.Handle(0);
  }

  Bus bus_;
  ActorConfig config_;
  std::vector<rlmsg::transition_batch_t> batches_;
  std::vector<rlmsg::stats_actor_t> stats_;
};

TEST_F(ActorTest, PublishesFullBatchesOfConsistentTransitions) {
  Actor actor(config_, &bus_);
  for (int i = 0; i < 100; ++i) actor.StepEnvs();
  bus_.Handle(0);
  ASSERT_EQ(batches_.size(), 100U / 16U);
  for (const auto& b : batches_) {
    EXPECT_EQ(b.count, 16);
    EXPECT_EQ(b.obs_size, 4);
    EXPECT_EQ(b.num_values, 64);
  }
  // Within an episode, a transition's next observation is the next transition's observation.
  const auto& b = batches_[0];
  for (int i = 0; i + 1 < b.count; ++i) {
    if (b.discount[static_cast<size_t>(i)] == 0.0f) continue;  // episode ended
    if (b.episode_id[static_cast<size_t>(i)] != b.episode_id[static_cast<size_t>(i + 1)]) continue;
    for (int k = 0; k < 4; ++k) {
      EXPECT_EQ(b.next_obs[static_cast<size_t>(i * 4 + k)],
                b.obs[static_cast<size_t>((i + 1) * 4 + k)]);
    }
  }
  EXPECT_EQ(actor.env_steps(), 100);
  EXPECT_GT(actor.episodes(), 0);  // random CartPole episodes last about 22 steps
}

TEST_F(ActorTest, PausesWhenTheReplayAsksAndResumesAfter) {
  Actor actor(config_, &bus_);
  EXPECT_TRUE(actor.paused()) << "before the replay's first flow message";
  rlmsg::flow_control_t f{};
  f.insert_allowed = 0;
  SendFlow(&f);
  EXPECT_TRUE(actor.paused());
  f.insert_allowed = 1;
  f.insert_credit = -1;  // the ratio is not enforced
  SendFlow(&f);
  EXPECT_FALSE(actor.paused());
}

// Actor 1 of 2 takes half the insert credit (rounded up), less its transitions that the replay
// has not stored yet, and pauses once it has published that many more.
TEST_F(ActorTest, PausesAtItsShareOfTheInsertCredit) {
  config_.actor_id = 1;
  config_.num_actors = 2;
  Actor actor(config_, &bus_);
  while (actor.published() < 32) actor.StepEnvs();
  rlmsg::flow_control_t f{};
  f.insert_allowed = 1;
  f.insert_credit = 41;  // a share of 21
  f.num_actors = 2;
  f.actor_id = {0, 1};
  f.actor_inserts = {500, 16};  // 16 of this actor's 32 are still on the way
  SendFlow(&f);
  EXPECT_EQ(actor.insert_limit(), 32 + 21 - 16);
  EXPECT_FALSE(actor.paused());
  while (!actor.paused()) actor.StepEnvs();
  EXPECT_EQ(actor.published(), 48);  // one more batch of 16: 37 is within it
  // More stored under this id than it has published (a restarted actor): nothing on the way.
  f.actor_inserts = {500, 1000};
  f.insert_credit = 7;
  SendFlow(&f);
  EXPECT_EQ(actor.insert_limit(), 48 + 4);
  // A message that no longer names this actor: a replay restarted empty. What the actor
  // published until then is lost, not on the way.
  f.num_actors = 1;
  f.actor_id = {0};
  f.actor_inserts = {500};
  f.insert_credit = 200;
  SendFlow(&f);
  EXPECT_EQ(actor.insert_limit(), 48 + 100);
  // No credit without insert_allowed; no limit when the ratio is not enforced.
  f.insert_allowed = 0;
  SendFlow(&f);
  EXPECT_TRUE(actor.paused());
  f.insert_allowed = 1;
  f.insert_credit = -1;
  SendFlow(&f);
  EXPECT_FALSE(actor.paused());
}

// A replay restarted from its snapshot has stored fewer of this actor's transitions than the
// one before it: the difference is lost, and the actor does not wait for it forever.
TEST_F(ActorTest, GoesOnAfterTheReplayRestartsFromASnapshot) {
  Actor actor(config_, &bus_);
  rlmsg::flow_control_t f{};
  f.insert_allowed = 1;
  f.insert_credit = 1000;
  f.num_actors = 1;
  f.actor_id = {0};
  f.actor_inserts = {0};
  SendFlow(&f);
  while (actor.published() < 320) actor.StepEnvs();
  f.insert_credit = 10;  // nearly spent, 300 stored: 20 on the way
  f.actor_inserts = {300};
  SendFlow(&f);
  EXPECT_TRUE(actor.paused());
  // The restarted replay holds 200 (its snapshot's) and has credit again.
  f.insert_credit = 100;
  f.actor_inserts = {200};
  SendFlow(&f);
  EXPECT_EQ(actor.insert_limit(), 320 + 100);
  EXPECT_FALSE(actor.paused());
  // Transitions that were on the way arrive: nothing of its own counts twice.
  f.actor_inserts = {216};
  SendFlow(&f);
  EXPECT_EQ(actor.insert_limit(), actor.published() + 100);
}

TEST_F(ActorTest, SwitchesToACompleteWeightsVersionAndActsGreedily) {
  config_.exploration.mode = "constant";
  config_.exploration.end = 0.0;
  Actor actor(config_, &bus_);
  EXPECT_EQ(actor.weights_version(), -1);
  // A network whose output 1 is always far larger: the greedy action is always 1 (push right).
  std::mt19937 rng(1);
  nn::Sequential net = nn::MakeMlp(4, {8}, 2, &rng);
  std::vector<float> flat;
  net.GetFlat(&flat);
  std::fill(flat.begin(), flat.end(), 0.0f);
  flat.back() = 100.0f;  // bias of the last layer's output 1
  SendWeights(3, net, flat);
  EXPECT_EQ(actor.weights_version(), 3);
  for (int i = 0; i < 32; ++i) actor.StepEnvs();
  bus_.Handle(0);
  ASSERT_FALSE(batches_.empty());
  EXPECT_EQ(batches_[0].action_width, 1);
  for (float a : batches_[0].action) EXPECT_EQ(a, 1.0f);
}

TEST_F(ActorTest, RefusesWeightsOfANetworkThatDoesNotFitTheEnv) {
  Actor actor(config_, &bus_);
  std::mt19937 rng(1);
  nn::Sequential net = nn::MakeMlp(3, {8}, 2, &rng);  // 3 inputs, CartPole has 4
  std::vector<float> flat;
  net.GetFlat(&flat);
  SendWeights(1, net, flat);
  // Refused (counted), not merely not yet complete: a fitting version after it is taken.
  EXPECT_EQ(actor.weights_refused(), 1);
  EXPECT_EQ(actor.weights_version(), -1);
  nn::Sequential fits = nn::MakeMlp(4, {8}, 2, &rng);
  fits.GetFlat(&flat);
  SendWeights(2, fits, flat);
  EXPECT_EQ(actor.weights_refused(), 1);
  EXPECT_EQ(actor.weights_version(), 2);
}

// Chunks that claim a buffer other than the network the actor built (here 256 MB for a network
// of 58 floats) are refused before anything is allocated for them.
TEST_F(ActorTest, RefusesWeightsChunksOfAnotherSizeThanItsNetwork) {
  Actor actor(config_, &bus_);
  std::mt19937 rng(1);
  nn::Sequential net = nn::MakeMlp(4, {8}, 2, &rng);
  std::vector<float> flat;
  net.GetFlat(&flat);
  SendWeights(1, net, flat);
  ASSERT_EQ(actor.weights_version(), 1);
  rlmsg::weights_chunk_t huge = learner::MakeWeightChunks(2, net.Architecture(), flat)[0];
  huge.total_size = 1 << 26;
  huge.num_chunks = 1 << 14;
  bus_.Publish(channels::kWeights, &huge, Port::kBulk);
  // As many chunks as floats, each with one float: absurd, refused as well.
  rlmsg::weights_chunk_t many = learner::MakeWeightChunks(3, net.Architecture(), flat)[0];
  many.num_chunks = many.total_size + 1;
  bus_.Publish(channels::kWeights, &many, Port::kBulk);
  bus_.Handle(0);
  EXPECT_EQ(bus_.counters().invalid, 0) << "the bus let them through: the actor refused them";
  EXPECT_EQ(actor.weights_refused(), 2);
  EXPECT_EQ(actor.weights_version(), 1);
}

// A restarted actor, or an actor of a resumed run, takes up its step count from the replay's
// first flow message before it acts: the transitions stored from its id, one per step of its
// earlier lives. Its exploration schedule continues from there (here: past the random start,
// sigma annealed), and its count never goes back.
TEST_F(ActorTest, TakesUpItsStepCountFromTheReplayBeforeItActs) {
  config_.env_id = "Pendulum-v1";
  config_.actor_id = 1;
  config_.num_actors = 2;
  config_.n_step = 1;
  ExplorationConfig& e = config_.exploration;
  e.mode = "gaussian";
  e.start_steps = 500;
  e.sigma = 0.5;
  e.sigma_end = 0.1;
  e.sigma_anneal_steps = 1000;
  Actor actor(config_, &bus_);
  EXPECT_FALSE(actor.count_taken_up());
  EXPECT_DOUBLE_EQ(actor.exploration(), 1.0);  // as a fresh actor: the random start
  rlmsg::flow_control_t f{};
  f.insert_allowed = 1;
  f.insert_credit = 64;  // a share of 32
  f.num_actors = 2;
  f.actor_id = {0, 1};
  f.actor_inserts = {900, 700};
  SendFlow(&f);
  ASSERT_TRUE(actor.count_taken_up());
  EXPECT_EQ(actor.env_steps(), 700);
  EXPECT_EQ(actor.published(), 700);
  EXPECT_NEAR(actor.exploration(), 0.5 + (0.1 - 0.5) * 0.7, 1e-12);
  // Nothing of its own is on the way: its whole share is free.
  EXPECT_EQ(actor.insert_limit(), 700 + 32);
  while (!actor.paused()) actor.StepEnvs();
  EXPECT_EQ(actor.env_steps(), 732);
  // A replay restarted from an older snapshot holds fewer: the count does not go back.
  f.actor_inserts = {900, 650};
  SendFlow(&f);
  EXPECT_EQ(actor.env_steps(), 732);
  actor.PublishStats();
  bus_.Handle(0);
  ASSERT_FALSE(stats_.empty());
  EXPECT_EQ(stats_.back().env_steps, 732);
  EXPECT_NEAR(stats_.back().epsilon, 0.5 + (0.1 - 0.5) * 0.732, 1e-12);
}

// A stopping actor sends every step it took, the pending n-step returns as truncations, so that
// the replay's count of its transitions is its step count.
TEST_F(ActorTest, SendsEveryStepItTookWhenItStops) {
  config_.n_step = 3;
  config_.max_steps = 50;
  Actor actor(config_, &bus_);
  rlmsg::flow_control_t f{};
  f.insert_allowed = 1;
  f.insert_credit = -1;  // the ratio is not enforced
  bus_.Publish(channels::kFlow, &f);
  actor.Run();
  bus_.Handle(0);
  EXPECT_GE(actor.env_steps(), 50);
  EXPECT_EQ(actor.published(), actor.env_steps());
  int64_t received = 0;
  for (const auto& b : batches_) received += b.count;
  EXPECT_EQ(received, actor.env_steps());
  // The last transition bootstraps from the last observation (a truncation, not a terminal).
  ASSERT_FALSE(batches_.empty());
  EXPECT_GT(batches_.back().discount.back(), 0.0f);
}

TEST_F(ActorTest, PublishesStatsWithItsCounters) {
  Actor actor(config_, &bus_);
  for (int i = 0; i < 50; ++i) actor.StepEnvs();
  actor.PublishStats();
  bus_.Handle(0);
  ASSERT_EQ(stats_.size(), 1U);
  EXPECT_EQ(stats_[0].env_steps, 50);
  EXPECT_EQ(stats_[0].transitions_published, 48);
  EXPECT_DOUBLE_EQ(stats_[0].epsilon, 0.4);
}

TEST_F(ActorTest, RefusesAnEpsilonPolicyOnAContinuousEnvAndNoiseOnADiscreteOne) {
  config_.env_id = "LunarLanderContinuous-v3";
  EXPECT_THROW(Actor(config_, &bus_), std::invalid_argument);
  config_.env_id = "CartPole-v1";
  config_.exploration.mode = "gaussian";
  EXPECT_THROW(Actor(config_, &bus_), std::invalid_argument);
}

// Continuous actions: random within the bounds during the start steps, then the network's action
// plus noise, clipped to the bounds; they travel as action_dim floats.
TEST_F(ActorTest, ActsInAContinuousEnvWithNoiseClippedToTheBounds) {
  config_.env_id = "LunarLanderContinuous-v3";
  config_.exploration.mode = "gaussian";
  config_.exploration.sigma = 0.1;
  config_.exploration.start_steps = 20;
  config_.n_step = 1;
  Actor actor(config_, &bus_);
  // Output 0 far above its bound (main engine: clipped to 1), output 1 at 0.5 (+ noise).
  std::mt19937 rng(1);
  nn::Sequential net = nn::MakeMlp(8, {8}, 2, &rng);
  std::vector<float> flat;
  net.GetFlat(&flat);
  std::fill(flat.begin(), flat.end(), 0.0f);
  flat[flat.size() - 2] = 100.0f;
  flat[flat.size() - 1] = 0.5f;
  SendWeights(1, net, flat);
  ASSERT_EQ(actor.weights_version(), 1);
  EXPECT_DOUBLE_EQ(actor.exploration(), 1.0);  // random start
  for (int i = 0; i < 200; ++i) actor.StepEnvs();
  bus_.Handle(0);
  std::vector<float> actions;
  for (const auto& b : batches_) {
    EXPECT_EQ(b.action_width, 2);
    actions.insert(actions.end(), b.action.begin(), b.action.end());
  }
  ASSERT_GE(actions.size(), 2U * 150U);
  int random_start = 0;
  double sum = 0, sum_sq = 0;
  int n = 0;
  for (size_t i = 0; i < actions.size() / 2; ++i) {
    const float main = actions[2 * i], side = actions[2 * i + 1];
    EXPECT_GE(main, -1.0f);
    EXPECT_LE(main, 1.0f);
    EXPECT_GE(side, -1.0f);
    EXPECT_LE(side, 1.0f);
    if (i < 20) {
      random_start += main != 1.0f;
      continue;
    }
    EXPECT_EQ(main, 1.0f) << i;  // mu far above the bound: clipped
    sum += side;
    sum_sq += side * side;
    ++n;
  }
  EXPECT_GT(random_start, 15);  // uniform draws are hardly ever exactly the bound
  // The side engine: mu 0.5 plus noise of sigma 0.1 x half-range 1.
  const double mean = sum / n;
  const double sd = std::sqrt(sum_sq / n - mean * mean);
  EXPECT_NEAR(mean, 0.5, 0.03);
  EXPECT_NEAR(sd, 0.1, 0.03);
}

TEST_F(ActorTest, ActsInLunarLanderWithItsEightObservationsAndFourActions) {
  config_.env_id = "LunarLander-v3";
  Actor actor(config_, &bus_);
  for (int i = 0; i < 64; ++i) actor.StepEnvs();
  bus_.Handle(0);
  ASSERT_FALSE(batches_.empty());
  EXPECT_EQ(batches_[0].obs_size, 8);
  for (float a : batches_[0].action) {
    EXPECT_GE(a, 0.0f);
    EXPECT_LT(a, 4.0f);
    EXPECT_EQ(a, std::floor(a));
  }
}

// Pixel envs: frames travel once, transitions name them. Rebuilding every stack from the frames
// and replaying the transitions' actions in a second env with the same seed must give exactly
// the observations the env produced, stack by stack, across episode boundaries.
TEST(ActorPixelsTest, SendsEveryFrameOnceAndStacksThatRebuildTheEnvsObservations) {
  Bus bus(Memq());
  std::vector<rlmsg::transition_batch_t> batches;
  bus.Subscribe<rlmsg::transition_batch_t>(
      channels::kTransitions,
      [&batches](const rlmsg::transition_batch_t& m) { batches.push_back(m); });
  ActorConfig config;
  config.env_id = "Catch-v0+pixels(width=5,height=10,stack=3,max-pool=0)";
  config.batch_size = 8;
  config.seed = 4;
  Actor actor(config, &bus);
  for (int i = 0; i < 60; ++i) actor.StepEnvs();
  bus.Handle(0);
  ASSERT_FALSE(batches.empty());

  std::map<int64_t, std::vector<uint8_t>> frames;
  std::vector<int64_t> obs_ids, next_ids;
  std::vector<float> actions;
  std::vector<float> discounts;
  for (const auto& b : batches) {
    EXPECT_EQ(b.height, 10);
    EXPECT_EQ(b.width, 5);
    EXPECT_EQ(b.stack, 3);
    EXPECT_EQ(b.obs_size, 0);
    EXPECT_TRUE(b.obs.empty());
    for (int f = 0; f < b.num_frames; ++f) {
      const auto at = b.frames.begin() + f * 50;
      EXPECT_TRUE(
          frames.emplace(b.frame_id[static_cast<size_t>(f)], std::vector<uint8_t>(at, at + 50))
              .second)
          << "frame " << b.frame_id[static_cast<size_t>(f)] << " sent twice";
    }
    obs_ids.insert(obs_ids.end(), b.obs_frames.begin(), b.obs_frames.end());
    next_ids.insert(next_ids.end(), b.next_obs_frames.begin(), b.next_obs_frames.end());
    actions.insert(actions.end(), b.action.begin(), b.action.end());
    discounts.insert(discounts.end(), b.discount.begin(), b.discount.end());
  }
  // 60 steps in episodes of 9: 56 transitions published in 7 batches. They carry the frames
  // queued until the 56th step: one per step and one per reset (the first, and after steps 9,
  // 18, ..., 54), each once.
  ASSERT_EQ(actions.size(), 56U);
  EXPECT_EQ(frames.size(), 56U + 7U);

  // Stacks as the bytes of an observation, from the frames the ids name.
  const auto stack_bytes = [&frames](const int64_t* ids) {
    std::vector<uint8_t> bytes;
    for (int k = 0; k < 3; ++k) {
      const auto it = frames.find(ids[k]);
      EXPECT_NE(it, frames.end()) << "unknown frame id " << ids[k];
      if (it != frames.end()) bytes.insert(bytes.end(), it->second.begin(), it->second.end());
    }
    return bytes;
  };
  const auto env_bytes = [](const envs::Env& env) {
    std::vector<uint8_t> bytes;
    for (float v : env.observation()) bytes.push_back(static_cast<uint8_t>(std::lround(v * 255)));
    return bytes;
  };
  auto replica = envs::MakeEnv(config.env_id);
  replica->Reset(TrainingSeed(config.seed, 0, 0));
  int episode_starts = 0;
  for (size_t i = 0; i < actions.size(); ++i) {
    const int64_t* ids = &obs_ids[3 * i];
    if (ids[0] == ids[2]) ++episode_starts;  // the first frame, repeated
    EXPECT_EQ(stack_bytes(ids), env_bytes(*replica)) << "transition " << i;
    const envs::StepResult r = replica->Step(std::span<const float>(&actions[i], 1));
    EXPECT_EQ(stack_bytes(&next_ids[3 * i]), env_bytes(*replica)) << "transition " << i;
    EXPECT_EQ(discounts[i] == 0.0f, r.terminated) << "transition " << i;
    if (r.terminated || r.truncated) replica->Reset();
  }
  EXPECT_EQ(episode_starts, 7);
}

// Catch's episodes last 9 steps; the later env cuts them at 3. Episodes that begin from step 20
// on are played on it: the first episode end at or after step 20 is step 27's.
TEST(ActorLaterEnvTest, PlaysTheEpisodesThatBeginAfterItsStepsOnTheLaterEnv) {
  Bus bus(Memq());
  ActorConfig config;
  config.env_id = "Catch-v0+pixels(width=5,height=10,stack=3,max-pool=0)";
  config.later_env_id = "Catch-v0+pixels(width=5,height=10,stack=3,max-pool=0,time-limit=3)";
  config.later_env_after = 20;
  Actor actor(config, &bus);
  for (int i = 0; i < 27; ++i) actor.StepEnvs();
  EXPECT_EQ(actor.episodes(), 3);
  for (int i = 0; i < 33; ++i) actor.StepEnvs();
  EXPECT_EQ(actor.episodes(), 3 + 11);

  config.later_env_id.clear();
  Actor without(config, &bus);
  for (int i = 0; i < 60; ++i) without.StepEnvs();
  EXPECT_EQ(without.episodes(), 6);
}

TEST(ActorLaterEnvTest, RefusesALaterEnvWithOtherObservationsOrActions) {
  Bus bus(Memq());
  ActorConfig config;
  config.env_id = "Catch-v0+pixels(width=5,height=10,stack=3,max-pool=0)";
  config.later_env_id = "Catch-v0+pixels(width=6,height=10,stack=3,max-pool=0)";
  EXPECT_THROW(Actor(config, &bus), std::invalid_argument);
  config.later_env_id = "CartPole-v1";
  EXPECT_THROW(Actor(config, &bus), std::invalid_argument);
  config.later_env_id = config.env_id;
  config.later_env_after = -1;
  EXPECT_THROW(Actor(config, &bus), std::invalid_argument);
}

TEST(ActorConfigTest, RefusesAnActorIdOutsideTheRun) {
  ActorConfig c;
  c.num_actors = 2;
  c.actor_id = 2;
  EXPECT_THROW(c.Validate(), std::invalid_argument);
}

}  // namespace
}  // namespace rl::actor
