#include "actor/actor.h"

#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "common/channels.h"
#include "learner/weights_publisher.h"
#include "nn/sequential.h"
#include "rlmsg/flow_control_t.hpp"
#include "rlmsg/stats_actor_t.hpp"

namespace rl::actor {
namespace {

BusConfig Memq() {
  BusConfig c;
  c.url = "memq://";
  c.bulk_url = "memq://";
  c.run_id = 5;
  c.sender = "actor-0";
  return c;
}

class ActorTest : public ::testing::Test {
 protected:
  ActorTest() : bus_(Memq()) {
    config_.batch_size = 16;
    bus_.Subscribe<rlmsg::transition_batch_t>(
        channels::kTransitions,
        [this](const rlmsg::transition_batch_t& m) { batches_.push_back(m); });
  }
  Bus bus_;
  ActorConfig config_;
  std::vector<rlmsg::transition_batch_t> batches_;
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
  EXPECT_FALSE(actor.paused());
  rlmsg::flow_control_t f{};
  f.insert_allowed = 0;
  bus_.Publish(channels::kFlow, &f);
  bus_.Handle(0);
  EXPECT_TRUE(actor.paused());
  f.insert_allowed = 1;
  bus_.Publish(channels::kFlow, &f);
  bus_.Handle(0);
  EXPECT_FALSE(actor.paused());
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
  for (auto& c : learner::MakeWeightChunks(3, net.Architecture(), flat)) {
    bus_.Publish(channels::kWeights, &c, Port::kBulk);
  }
  bus_.Handle(0);
  EXPECT_EQ(actor.weights_version(), 3);
  for (int i = 0; i < 32; ++i) actor.StepEnvs();
  bus_.Handle(0);
  ASSERT_FALSE(batches_.empty());
  for (int32_t a : batches_[0].action) EXPECT_EQ(a, 1);
}

TEST_F(ActorTest, RefusesWeightsOfANetworkThatDoesNotFitTheEnv) {
  Actor actor(config_, &bus_);
  std::mt19937 rng(1);
  nn::Sequential net = nn::MakeMlp(3, {8}, 2, &rng);  // 3 inputs, CartPole has 4
  std::vector<float> flat;
  net.GetFlat(&flat);
  for (auto& c : learner::MakeWeightChunks(1, net.Architecture(), flat)) {
    bus_.Publish(channels::kWeights, &c, Port::kBulk);
  }
  bus_.Handle(0);
  EXPECT_EQ(actor.weights_version(), -1);
}

TEST_F(ActorTest, PublishesStatsWithItsCounters) {
  std::vector<rlmsg::stats_actor_t> stats;
  bus_.Subscribe<rlmsg::stats_actor_t>(
      channels::kStatsActor, [&stats](const rlmsg::stats_actor_t& s) { stats.push_back(s); });
  Actor actor(config_, &bus_);
  for (int i = 0; i < 50; ++i) actor.StepEnvs();
  actor.PublishStats();
  bus_.Handle(0);
  ASSERT_EQ(stats.size(), 1U);
  EXPECT_EQ(stats[0].env_steps, 50);
  EXPECT_EQ(stats[0].transitions_published, 48);
  EXPECT_DOUBLE_EQ(stats[0].epsilon, 0.4);
}

TEST_F(ActorTest, RefusesAnEnvWithContinuousActions) {
  config_.env_id = "LunarLanderContinuous-v3";
  EXPECT_THROW(Actor(config_, &bus_), std::invalid_argument);
}

TEST_F(ActorTest, ActsInLunarLanderWithItsEightObservationsAndFourActions) {
  config_.env_id = "LunarLander-v3";
  Actor actor(config_, &bus_);
  for (int i = 0; i < 64; ++i) actor.StepEnvs();
  bus_.Handle(0);
  ASSERT_FALSE(batches_.empty());
  EXPECT_EQ(batches_[0].obs_size, 8);
  for (int32_t a : batches_[0].action) {
    EXPECT_GE(a, 0);
    EXPECT_LT(a, 4);
  }
}

TEST(ActorConfigTest, RefusesAnActorIdOutsideTheRun) {
  ActorConfig c;
  c.num_actors = 2;
  c.actor_id = 2;
  EXPECT_THROW(c.Validate(), std::invalid_argument);
}

}  // namespace
}  // namespace rl::actor
