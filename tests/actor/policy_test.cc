#include "actor/policy.h"

#include <cmath>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "envs/specs.h"

namespace rl::actor {
namespace {

// A linear network in -> out whose outputs are its biases (weights zero).
nn::Sequential ConstantNet(int in, std::vector<float> outputs) {
  std::mt19937 rng(1);
  nn::Sequential net = nn::MakeMlp(in, {4}, static_cast<int>(outputs.size()), &rng);
  std::vector<float> flat;
  net.GetFlat(&flat);
  std::fill(flat.begin(), flat.end(), 0.0f);
  std::copy(outputs.begin(), outputs.end(), flat.end() - static_cast<long>(outputs.size()));
  net.SetFlat(flat.data(), flat.size());
  return net;
}

ExplorationConfig Gaussian(double sigma, int64_t start_steps = 0) {
  ExplorationConfig c;
  c.mode = "gaussian";
  c.sigma = c.sigma_end = sigma;
  c.start_steps = start_steps;
  return c;
}

TEST(PolicyTest, GaussianNoiseStaysInPerDimensionBoundsAndHasItsScale) {
  const envs::EnvSpec spec = envs::CarRacingSpec(true);  // steer [-1, 1], gas and brake [0, 1]
  auto policy = MakePolicy(spec, Gaussian(0.2), 0, 1, 7);
  policy->SetNetwork(ConstantNet(spec.observation_size, {0.0f, 0.5f, 0.95f}));
  const std::vector<float> obs(static_cast<size_t>(spec.observation_size), 0.0f);
  std::vector<float> a(3);
  double sum[3] = {}, sq[3] = {};
  int at_brake_bound = 0;
  const int n = 4000;
  for (int i = 0; i < n; ++i) {
    policy->Act(obs, 100, a);
    for (int d = 0; d < 3; ++d) {
      EXPECT_GE(a[d], spec.action_low[d]);
      EXPECT_LE(a[d], spec.action_high[d]);
      sum[d] += a[d];
      sq[d] += a[d] * a[d];
    }
    at_brake_bound += a[2] == 1.0f;
  }
  // sigma_d = 0.2 * half-range: 0.2 for steer, 0.1 for gas (neither clipped much).
  EXPECT_NEAR(sum[0] / n, 0.0, 0.02);
  EXPECT_NEAR(std::sqrt(sq[0] / n - sum[0] * sum[0] / n / n), 0.2, 0.02);
  EXPECT_NEAR(sum[1] / n, 0.5, 0.01);
  EXPECT_NEAR(std::sqrt(sq[1] / n - sum[1] * sum[1] / n / n), 0.1, 0.01);
  // Brake at 0.95 + N(0, 0.1^2): about 31 % of the draws land on the bound 1.
  EXPECT_NEAR(static_cast<double>(at_brake_bound) / n, 0.31, 0.04);
  EXPECT_FALSE(policy->last_value().has_value());
}

TEST(PolicyTest, GaussianNoiseFollowsItsScheduleStartAndSpread) {
  ExplorationConfig c = Gaussian(0.5, 1000);
  c.sigma_end = 0.1;
  c.sigma_anneal_steps = 10000;
  c.noise_spread = 0.25;
  const envs::EnvSpec spec = envs::PendulumSpec();
  auto first = MakePolicy(spec, c, 0, 3, 1);
  auto last = MakePolicy(spec, c, 2, 3, 1);
  EXPECT_DOUBLE_EQ(first->exploration(999), 1.0);  // random start
  EXPECT_DOUBLE_EQ(first->exploration(1000), 0.5 + (0.1 - 0.5) * 0.1);
  EXPECT_DOUBLE_EQ(first->exploration(5000), 0.5 + (0.1 - 0.5) * 0.5);
  EXPECT_DOUBLE_EQ(first->exploration(20000), 0.1);
  EXPECT_DOUBLE_EQ(last->exploration(20000), 0.025);
  // During the start, actions are uniform on the bounds even with a network.
  first->SetNetwork(ConstantNet(3, {1.9f}));
  std::vector<float> a(1);
  const std::vector<float> obs = {1, 0, 0};
  double sum = 0;
  for (int i = 0; i < 2000; ++i) {
    first->Act(obs, 10, a);
    EXPECT_GE(a[0], -2.0f);
    EXPECT_LE(a[0], 2.0f);
    sum += a[0];
  }
  EXPECT_NEAR(sum / 2000, 0.0, 0.1);
}

TEST(PolicyTest, EvaluationIsDeterministicForContinuousAndEpsilonForDiscrete) {
  const envs::EnvSpec pendulum = envs::PendulumSpec();
  auto policy = MakePolicy(pendulum, EvaluationExploration(pendulum, 0.05), 0, 1, 3);
  policy->SetNetwork(ConstantNet(3, {0.7f}));
  std::vector<float> a(1);
  for (int i = 0; i < 100; ++i) {
    policy->Act(std::vector<float>{1, 0, 0}, 0, a);
    EXPECT_EQ(a[0], 0.7f);
  }
  const envs::EnvSpec cartpole = envs::CartPoleSpec();
  auto greedy = MakePolicy(cartpole, EvaluationExploration(cartpole, 0.25), 0, 1, 3);
  greedy->SetNetwork(ConstantNet(4, {0.0f, 2.0f}));
  int ones = 0;
  for (int i = 0; i < 4000; ++i) {
    greedy->Act(std::vector<float>{0, 0, 0, 0}, 0, a);
    ones += a[0] == 1.0f;
    ASSERT_TRUE(greedy->last_value().has_value());
    EXPECT_EQ(*greedy->last_value(), a[0] == 1.0f ? 2.0 : 0.0);
  }
  // Greedy 1 except a random action (half of them 0) a quarter of the time.
  EXPECT_NEAR(ones / 4000.0, 1.0 - 0.25 / 2, 0.02);
}

TEST(PolicyTest, RefusesMismatchedExplorationAndNetworks) {
  EXPECT_THROW(MakePolicy(envs::PendulumSpec(), ExplorationConfig{}, 0, 1, 1),
               std::invalid_argument);
  EXPECT_THROW(MakePolicy(envs::CartPoleSpec(), Gaussian(0.1), 0, 1, 1), std::invalid_argument);
  auto policy = MakePolicy(envs::PendulumSpec(), Gaussian(0.1), 0, 1, 1);
  EXPECT_FALSE(policy->CheckNetwork(ConstantNet(3, {0.0f, 0.0f})).empty());  // 2 outputs
  EXPECT_FALSE(policy->CheckNetwork(ConstantNet(4, {0.0f})).empty());        // 4 inputs
  EXPECT_TRUE(policy->CheckNetwork(ConstantNet(3, {0.0f})).empty());
  EXPECT_THROW(policy->SetNetwork(ConstantNet(4, {0.0f})), std::invalid_argument);
  EXPECT_FALSE(policy->has_network());
}

TEST(PolicyTest, CarRacingMismatchNamesThePedalsOption) {
  // A checkpoint of one action form scored with the other's env string: the error says which.
  const envs::EnvSpec two_pedals = envs::CarRacingSpec(true);
  const envs::EnvSpec one_pedal = envs::CarRacingSpec(true, /*pedals=*/true);
  const int in = two_pedals.observation_size;
  const std::string old_net =
      MakePolicy(one_pedal, Gaussian(0.1), 0, 1, 1)->CheckNetwork(ConstantNet(in, {0, 0, 0}));
  EXPECT_NE(old_net.find("drop pedals=1"), std::string::npos) << old_net;
  const std::string new_net =
      MakePolicy(two_pedals, Gaussian(0.1), 0, 1, 1)->CheckNetwork(ConstantNet(in, {0, 0}));
  EXPECT_NE(new_net.find("add pedals=1"), std::string::npos) << new_net;
  EXPECT_TRUE(
      MakePolicy(one_pedal, Gaussian(0.1), 0, 1, 1)->CheckNetwork(ConstantNet(in, {0, 0})).empty());
}

}  // namespace
}  // namespace rl::actor
