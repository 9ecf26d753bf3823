#include "learner/dqn.h"

#include <random>
#include <stdexcept>
#include <string>
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

// Bytes in, divided by 255 on the way: the same update as the equivalent float batch.
TEST(DqnTest, APixelBatchTrainsLikeTheSameBatchOfFloats) {
  DqnConfig c;
  c.network = "conv2d(2,4,3,1,1,3,3),relu,flatten,linear(36,3)";
  c.seed = 5;
  Dqn from_bytes(18, 3, c);
  Dqn from_floats(18, 3, c);
  std::mt19937 rng(9);
  std::uniform_int_distribution<int> byte(0, 255);
  const int n = 8;
  std::vector<uint8_t> obs(18 * n), next_obs(18 * n);
  for (auto& v : obs) v = static_cast<uint8_t>(byte(rng));
  for (auto& v : next_obs) v = static_cast<uint8_t>(byte(rng));
  std::vector<float> obs_f(obs.size()), next_f(next_obs.size());
  for (size_t i = 0; i < obs.size(); ++i) obs_f[i] = static_cast<float>(obs[i]) / 255.0f;
  for (size_t i = 0; i < next_obs.size(); ++i) {
    next_f[i] = static_cast<float>(next_obs[i]) / 255.0f;
  }
  const std::vector<int32_t> action = {0, 1, 2, 0, 1, 2, 0, 1};
  const std::vector<float> reward(n, 0.5f), discount(n, 0.9f);
  BatchView b;
  b.obs_size = 18;
  b.count = n;
  b.action = action.data();
  b.reward = reward.data();
  b.discount = discount.data();
  BatchView bytes = b;
  bytes.obs_pixels = obs.data();
  bytes.next_obs_pixels = next_obs.data();
  BatchView floats = b;
  floats.obs = obs_f.data();
  floats.next_obs = next_f.data();
  for (int i = 0; i < 3; ++i) {
    const UpdateResult rb = from_bytes.Update(bytes);
    const UpdateResult rf = from_floats.Update(floats);
    EXPECT_EQ(rb.loss, rf.loss);
  }
  std::vector<float> pb, pf;
  from_bytes.online().GetFlat(&pb);
  from_floats.online().GetFlat(&pf);
  EXPECT_EQ(pb, pf);
  EXPECT_THROW(from_bytes.Update(b), std::invalid_argument);  // no observations at all
}

// A pixel batch of n observations: 2 frames of 3 x 3 bytes each.
struct PixelBatch {
  std::vector<uint8_t> obs, next_obs;
  std::vector<int32_t> action;
  std::vector<float> reward, discount;
  BatchView view() const {
    BatchView b;
    b.obs_size = 18;
    b.count = static_cast<int>(action.size());
    b.frame_height = 3;
    b.frame_width = 3;
    b.obs_pixels = obs.data();
    b.next_obs_pixels = next_obs.data();
    b.action = action.data();
    b.reward = reward.data();
    b.discount = discount.data();
    return b;
  }
};

// Flat frames (every pixel of an observation alike) when `flat`, else random bytes.
PixelBatch MakePixelBatch(bool flat, std::mt19937* rng) {
  constexpr int n = 8;
  std::uniform_int_distribution<int> byte(0, 255);
  PixelBatch p;
  for (int i = 0; i < n; ++i) {
    for (std::vector<uint8_t>* v : {&p.obs, &p.next_obs}) {
      const int level = byte(*rng);
      for (int k = 0; k < 18; ++k) v->push_back(static_cast<uint8_t>(flat ? level : byte(*rng)));
    }
    p.action.push_back(i % 3);
    p.reward.push_back(0.5f);
    p.discount.push_back(0.9f);
  }
  return p;
}

std::vector<float> TrainThree(const DqnConfig& c, const PixelBatch& p) {
  Dqn dqn(18, 3, c);
  for (int i = 0; i < 3; ++i) dqn.Update(p.view());
  std::vector<float> flat;
  dqn.online().GetFlat(&flat);
  return flat;
}

TEST(DqnTest, RandomShiftsMoveThePixelsAndNothingElse) {
  DqnConfig plain;
  plain.network = "conv2d(2,4,3,1,1,3,3),relu,flatten,linear(36,3)";
  plain.seed = 5;
  DqnConfig shifted = plain;
  shifted.augment_shift = 1;
  std::mt19937 rng(9);
  // A shift leaves a flat frame as it is (the edges repeat), so training is the same.
  const PixelBatch flat = MakePixelBatch(true, &rng);
  EXPECT_EQ(TrainThree(shifted, flat), TrainThree(plain, flat));
  // On random frames the shifts change what the network sees, the same way for the same seed.
  const PixelBatch noise = MakePixelBatch(false, &rng);
  EXPECT_NE(TrainThree(shifted, noise), TrainThree(plain, noise));
  EXPECT_EQ(TrainThree(shifted, noise), TrainThree(shifted, noise));
}

TEST(DqnTest, RandomShiftsNeedPixelBatchesWithTheirFrameSize) {
  DqnConfig c;
  c.network = "conv2d(2,4,3,1,1,3,3),relu,flatten,linear(36,3)";
  c.augment_shift = 2;
  Dqn dqn(18, 3, c);
  std::mt19937 rng(1);
  const PixelBatch p = MakePixelBatch(false, &rng);
  BatchView no_size = p.view();
  no_size.frame_height = 0;
  EXPECT_THROW(dqn.Update(no_size), std::invalid_argument);
  std::vector<float> floats(18 * 8, 0.5f);
  BatchView of_floats = p.view();
  of_floats.obs_pixels = nullptr;
  of_floats.next_obs_pixels = nullptr;
  of_floats.obs = floats.data();
  of_floats.next_obs = floats.data();
  EXPECT_THROW(dqn.Update(of_floats), std::invalid_argument);
  EXPECT_NO_THROW(dqn.Update(p.view()));
}

TEST(DqnConfigTest, RefusesBadSettings) {
  DqnConfig c;
  c.optimizer = "sgd";
  EXPECT_THROW(c.Validate(), std::invalid_argument);
  c = DqnConfig();
  c.tau = 0;
  EXPECT_THROW(c.Validate(), std::invalid_argument);
  c = DqnConfig();
  c.augment_shift = -1;
  EXPECT_THROW(c.Validate(), std::invalid_argument);
}

}  // namespace
}  // namespace rl::learner
