#include "learner/dqn.h"

#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "tests/learner/owned_batch.h"

namespace rl::learner {
namespace {

// A two-state chain: from s0 (obs [1,0]) action 1 gives reward 0 and leads to s1; action 0 ends
// the episode with reward 0.5. From s1 (obs [0,1]) action 0 ends with reward 1, action 1 ends
// with reward 0. With gamma 0.9: Q(s1) = (1, 0), Q(s0) = (0.5, 0.9).
// n random transitions of the chain (view(1): one action index each).
OwnedBatch MakeChain(int n, std::mt19937* rng) {
  OwnedBatch c;
  c.obs = nn::Matrix::Zero(2, n);
  c.next_obs = nn::Matrix::Zero(2, n);
  std::uniform_int_distribution<int> coin(0, 1);
  for (int i = 0; i < n; ++i) {
    const bool in_s0 = coin(*rng) == 0;
    const int a = coin(*rng);
    c.obs(in_s0 ? 0 : 1, i) = 1.0f;
    c.action.push_back(static_cast<float>(a));
    if (in_s0 && a == 1) {
      c.next_obs(1, i) = 1.0f;
      c.reward.push_back(0.0f);
      c.discount.push_back(0.9f);
    } else {
      c.reward.push_back(in_s0 ? 0.5f : (a == 0 ? 1.0f : 0.0f));
      c.discount.push_back(0.0f);
    }
  }
  return c;
}

// A Dqn for the chain with one hidden layer of 4 units.
Dqn SmallDqn() {
  DqnConfig c;
  c.hidden = {4};
  return Dqn(2, 2, c);
}

void ExpectChainSolved(const DqnConfig& config) {
  Dqn dqn(2, 2, config);
  std::mt19937 rng(3);
  for (int i = 0; i < 3000; ++i) {
    dqn.Update(MakeChain(32, &rng).view(1));
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
  Dqn dqn = SmallDqn();
  std::mt19937 rng(4);
  OwnedBatch b = MakeChain(8, &rng);
  // Zero weights: no gradient, so the parameters must not move.
  b.weight.assign(8, 0.0f);
  const std::vector<float> before = Flat(dqn.online());
  const UpdateResult r = dqn.Update(b.view(1));
  EXPECT_EQ(Flat(dqn.online()), before);
  EXPECT_FLOAT_EQ(r.loss, 0.0f);
  ASSERT_EQ(dqn.last_td_errors().size(), 8U);
  EXPECT_GT(dqn.last_td_errors()[0] + dqn.last_td_errors()[1], 0.0f);
}

// A batch that does not fit is refused before anything changes: observation size, an action
// index out of range or not an integer, an action width other than 1.
TEST(DqnTest, RefusesABatchThatDoesNotFitTheNetworkAndChangesNothing) {
  Dqn dqn = SmallDqn();
  std::mt19937 rng(4);
  OwnedBatch b = MakeChain(4, &rng);
  const std::vector<float> before = Flat(dqn.online());
  Batch v = b.view(1);
  nn::Matrix three(3, 4);
  three.setZero();
  v.obs = &three;
  EXPECT_THROW(dqn.Update(v), std::invalid_argument);
  b.action[0] = 5;
  EXPECT_THROW(dqn.Update(b.view(1)), std::invalid_argument);
  b.action[0] = 0.5f;
  EXPECT_THROW(dqn.Update(b.view(1)), std::invalid_argument);
  b.action[0] = 1;
  v = b.view(2);
  EXPECT_THROW(dqn.Update(v), std::invalid_argument);
  EXPECT_EQ(Flat(dqn.online()), before);
  EXPECT_EQ(dqn.updates(), 0);
  EXPECT_NO_THROW(dqn.Update(b.view(1)));
  EXPECT_EQ(dqn.updates(), 1);
}

TEST(DqnTest, LearnsTheChainWithADuelingMlp) {
  DqnConfig c;
  c.hidden = {32, 32};
  c.dueling = true;
  c.target_update_period = 100;
  EXPECT_EQ(QNetworkArchitecture(c, 2, 2), "linear(2,32),relu,dueling(32,32,2)");
  ExpectChainSolved(c);
}

TEST(DqnTest, LearnsTheChainFromAnArchitectureString) {
  DqnConfig c;
  c.network = "linear(2,16),tanh,linear(16,2)";
  c.target_update_period = 100;
  ExpectChainSolved(c);
}

TEST(DqnTest, NamesTheQNetworksItKnowsAndRefusesMismatches) {
  DqnConfig c;
  c.hidden = {8};
  EXPECT_EQ(QNetworkArchitecture(c, 3, 2), "linear(3,8),relu,linear(8,2)");
  c.network = "nature";
  EXPECT_NE(QNetworkArchitecture(c, 4 * 84 * 84, 6).find("conv2d(4,32,8,4,0,84,84)"),
            std::string::npos);
  EXPECT_THROW(QNetworkArchitecture(c, 3 * 84 * 84, 6), std::invalid_argument);
  c.network = "grasp";
  EXPECT_NE(QNetworkArchitecture(c, 2 * 40 * 40, 7).find("conv2d(2,32,8,4,0,40,40)"),
            std::string::npos);
  EXPECT_THROW(QNetworkArchitecture(c, 100, 7), std::invalid_argument);
  c.network = "grasp48";
  c.dueling = true;
  const std::string grasp48 = QNetworkArchitecture(c, 4 * 48 * 48, 7);
  EXPECT_NE(grasp48.find("conv2d(4,16,5,2,2,48,48)"), std::string::npos);
  EXPECT_NE(grasp48.find("dueling(1152,256,7)"), std::string::npos);
  EXPECT_THROW(QNetworkArchitecture(c, 4 * 40 * 40, 7), std::invalid_argument);
  c.dueling = false;
  c.network = "resnet";
  EXPECT_THROW(QNetworkArchitecture(c, 3, 2), std::invalid_argument);
  // An architecture string that does not fit the env is refused when the Dqn is built.
  c.network = "linear(5,2)";
  EXPECT_THROW(Dqn(3, 2, c), std::invalid_argument);
}

TEST(DqnConfigTest, RefusesBadSettings) {
  DqnConfig c;
  c.optimizer = "sgd";
  EXPECT_THROW(c.Validate(), std::invalid_argument);
  c = DqnConfig();
  c.tau = 0;
  EXPECT_THROW(c.Validate(), std::invalid_argument);
  c = DqnConfig();
  c.hidden = {0};
  EXPECT_THROW(c.Validate(), std::invalid_argument);
}

// SaveState then LoadState into a fresh DQN (another seed): the next updates are bit-identical,
// with Adam's and RMSprop's states.
TEST(DqnTest, RestoredStateContinuesBitForBit) {
  for (const std::string optimizer : {"adam", "rmsprop"}) {
    SCOPED_TRACE(optimizer);
    DqnConfig config;
    config.optimizer = optimizer;
    config.target_update_period = 5;
    config.seed = 1;
    Dqn a(2, 2, config);
    std::mt19937 rng(3);
    for (int i = 0; i < 7; ++i) {
      a.Update(MakeChain(16, &rng).view(1));
    }
    StateFile state("dqn");
    a.SaveState(&state);
    config.seed = 2;
    Dqn restored(2, 2, config);
    restored.LoadState(state);
    EXPECT_EQ(restored.updates(), 7);
    for (int i = 0; i < 6; ++i) {  // across a target refresh (update 10)
      const OwnedBatch b = MakeChain(16, &rng);
      EXPECT_EQ(a.Update(b.view(1)).loss, restored.Update(b.view(1)).loss) << i;
    }
    EXPECT_EQ(Flat(a.online()), Flat(restored.online()));
    DqnConfig other = config;
    other.hidden = {8};
    Dqn wrong(2, 2, other);
    EXPECT_THROW(wrong.LoadState(state), std::runtime_error);
  }
}

}  // namespace
}  // namespace rl::learner
