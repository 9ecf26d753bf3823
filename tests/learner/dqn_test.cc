#include "learner/dqn.h"

#include <random>
#include <vector>

#include <gtest/gtest.h>

namespace rl::learner {
namespace {

// A two-state chain: from s0 (obs [1,0]) action 1 gives reward 0 and leads to s1; action 0 ends
// the episode with reward 0.5. From s1 (obs [0,1]) action 0 ends with reward 1, action 1 ends
// with reward 0. With gamma 0.9: Q(s1) = (1, 0), Q(s0) = (0.5, 0.9).
struct ChainBatch {
  std::vector<float> obs, next_obs, reward, discount, weight;
  std::vector<int32_t> action;
  BatchView view() const {
    BatchView b;
    b.obs_size = 2;
    b.count = static_cast<int>(action.size());
    b.obs = obs.data();
    b.next_obs = next_obs.data();
    b.action = action.data();
    b.reward = reward.data();
    b.discount = discount.data();
    b.weight = weight.empty() ? nullptr : weight.data();
    return b;
  }
};

ChainBatch MakeChain(int n, std::mt19937* rng) {
  ChainBatch c;
  std::uniform_int_distribution<int> coin(0, 1);
  for (int i = 0; i < n; ++i) {
    const bool in_s0 = coin(*rng) == 0;
    const int a = coin(*rng);
    c.obs.insert(c.obs.end(), {in_s0 ? 1.0f : 0.0f, in_s0 ? 0.0f : 1.0f});
    c.action.push_back(a);
    if (in_s0 && a == 1) {
      c.next_obs.insert(c.next_obs.end(), {0.0f, 1.0f});
      c.reward.push_back(0.0f);
      c.discount.push_back(0.9f);
    } else {
      c.next_obs.insert(c.next_obs.end(), {0.0f, 0.0f});
      c.reward.push_back(in_s0 ? 0.5f : (a == 0 ? 1.0f : 0.0f));
      c.discount.push_back(0.0f);
    }
  }
  return c;
}

void ExpectChainSolved(const DqnConfig& config) {
  Dqn dqn(2, 2, config);
  std::mt19937 rng(3);
  for (int i = 0; i < 3000; ++i) {
    ChainBatch b = MakeChain(32, &rng);
    dqn.Update(b.view());
  }
  const float s0[2] = {1, 0};
  const float s1[2] = {0, 1};
  const nn::Matrix q0 = dqn.online().Predict(s0, 2);
  const nn::Matrix q1 = dqn.online().Predict(s1, 2);
  EXPECT_NEAR(q1(0, 0), 1.0f, 0.05f);
  EXPECT_NEAR(q1(1, 0), 0.0f, 0.05f);
  EXPECT_NEAR(q0(0, 0), 0.5f, 0.05f);
  EXPECT_NEAR(q0(1, 0), 0.9f, 0.05f);
}

TEST(DqnTest, LearnsTheQValuesOfATwoStateChain) {
  DqnConfig c;
  c.hidden = {16};
  c.target_update_period = 50;
  ExpectChainSolved(c);
}

TEST(DqnTest, LearnsTheChainWithoutDoubleDqnAndWithSoftUpdatesAndMse) {
  DqnConfig c;
  c.hidden = {16};
  c.double_dqn = false;
  c.loss = "mse";
  c.target_update_period = 1;
  c.tau = 0.05f;
  ExpectChainSolved(c);
}

TEST(DqnTest, LearnsTheChainWithCenteredRmsProp) {
  DqnConfig c;
  c.hidden = {16};
  c.optimizer = "rmsprop";
  c.learning_rate = 2.5e-3f;
  c.target_update_period = 50;
  ExpectChainSolved(c);
}

TEST(DqnTest, ReportsTdErrorsAndHonoursImportanceWeights) {
  DqnConfig c;
  c.hidden = {4};
  Dqn dqn(2, 2, c);
  std::mt19937 rng(4);
  ChainBatch b = MakeChain(8, &rng);
  // Zero weights: no gradient, so the parameters must not move.
  b.weight.assign(8, 0.0f);
  std::vector<float> before, after;
  dqn.online().GetFlat(&before);
  const UpdateResult r = dqn.Update(b.view());
  dqn.online().GetFlat(&after);
  EXPECT_EQ(before, after);
  EXPECT_FLOAT_EQ(r.loss, 0.0f);
  ASSERT_EQ(dqn.last_td_errors().size(), 8U);
  EXPECT_GT(dqn.last_td_errors()[0] + dqn.last_td_errors()[1], 0.0f);
}

TEST(DqnTest, RefusesABatchThatDoesNotFitTheNetwork) {
  DqnConfig c;
  c.hidden = {4};
  Dqn dqn(2, 2, c);
  std::mt19937 rng(4);
  ChainBatch b = MakeChain(4, &rng);
  BatchView v = b.view();
  v.obs_size = 3;
  EXPECT_THROW(dqn.Update(v), std::invalid_argument);
  b.action[0] = 5;
  EXPECT_THROW(dqn.Update(b.view()), std::invalid_argument);
}

TEST(DqnConfigTest, RefusesBadSettings) {
  DqnConfig c;
  c.optimizer = "sgd";
  EXPECT_THROW(c.Validate(), std::invalid_argument);
  c = DqnConfig();
  c.tau = 0;
  EXPECT_THROW(c.Validate(), std::invalid_argument);
}

}  // namespace
}  // namespace rl::learner
