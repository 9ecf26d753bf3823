#include "learner/td3.h"

#include <algorithm>
#include <cmath>
#include <random>
#include <stdexcept>
#include <vector>

#include <gtest/gtest.h>

#include "envs/specs.h"
#include "nn/parallel.h"
#include "tests/learner/owned_batch.h"

namespace rl::learner {
namespace {

// A 2-d observation, 2-d action env spec with an asymmetric box (as CarRacing's gas).
envs::EnvSpec SmallSpec() {
  envs::EnvSpec spec = envs::PendulumSpec();
  spec.id = "Small";
  spec.observation_size = 2;
  spec.action_dim = 2;
  spec.action_low = {-1.0f, 0.0f};
  spec.action_high = {1.0f, 1.0f};
  return spec;
}

Td3Config SmallConfig() {
  Td3Config c;
  c.hidden = {8, 8};
  c.target_noise = 0;  // deterministic targets unless a test turns it on
  c.seed = 3;
  return c;
}

// A batch of n random transitions of `spec`.
OwnedBatch RandomBatch(const envs::EnvSpec& spec, int n, std::mt19937* rng) {
  std::normal_distribution<float> normal;
  OwnedBatch b;
  b.obs.resize(spec.observation_size, n);
  b.next_obs.resize(spec.observation_size, n);
  for (Eigen::Index i = 0; i < b.obs.size(); ++i) {
    b.obs.data()[i] = normal(*rng);
    b.next_obs.data()[i] = normal(*rng);
  }
  for (int i = 0; i < n; ++i) {
    for (int d = 0; d < spec.action_dim; ++d) {
      const auto k = static_cast<size_t>(d);
      b.action.push_back(
          std::uniform_real_distribution<float>(spec.action_low[k], spec.action_high[k])(*rng));
    }
    b.reward.push_back(normal(*rng));
    // Terminal, bootstrapped one step, and bootstrapped after a 3-step return (or a truncation).
    b.discount.push_back(i % 3 == 0 ? 0.0f : (i % 3 == 1 ? 0.99f : 0.99f * 0.99f * 0.99f));
  }
  return b;
}

// y = r + discount * min(Q1'(s', a'), Q2'(s', a')) with a' = mu'(s') (no smoothing noise),
// computed with copies of the target networks as they were before the update.
TEST(Td3Test, TargetsAreTheClippedDoubleQOfTheTargetActorsAction) {
  const envs::EnvSpec spec = SmallSpec();
  Td3 td3(spec, SmallConfig());
  std::mt19937 rng(1);
  // Move the online networks away from the targets first, so that using the wrong ones shows.
  for (int k = 0; k < 4; ++k) td3.Update(RandomBatch(spec, 16, &rng).view(2));
  nn::Sequential actor_target = td3.actor_target();
  nn::ActionValueNet q1 = td3.critic_target(0);
  nn::ActionValueNet q2 = td3.critic_target(1);
  const OwnedBatch b = RandomBatch(spec, 9, &rng);
  td3.Update(b.view(2));
  const nn::Matrix next_action = actor_target.Forward(b.next_obs);
  const nn::Matrix v1 = q1.Forward(b.next_obs, next_action);
  const nn::Matrix v2 = q2.Forward(b.next_obs, next_action);
  ASSERT_EQ(td3.last_targets().size(), 9);
  int differ = 0;
  for (int i = 0; i < 9; ++i) {
    const auto k = static_cast<size_t>(i);
    const float expected = b.reward[k] + b.discount[k] * std::min(v1(0, i), v2(0, i));
    EXPECT_NEAR(td3.last_targets()[i], expected, 1e-5f) << "transition " << i;
    differ += v1(0, i) != v2(0, i);
    if (b.discount[k] == 0) {
      EXPECT_EQ(td3.last_targets()[i], b.reward[k]);
    }
  }
  EXPECT_GT(differ, 0);  // the two target critics differ, so the min matters
}

TEST(Td3Test, TargetSmoothingNoiseIsClipped) {
  const envs::EnvSpec spec = SmallSpec();
  Td3Config off = SmallConfig();
  Td3Config clipped = SmallConfig();
  clipped.target_noise = 10;  // huge noise, clipped to nothing
  clipped.target_noise_clip = 0;
  Td3 a(spec, off), b(spec, clipped);
  std::mt19937 rng(2);
  const OwnedBatch batch = RandomBatch(spec, 8, &rng);
  a.Update(batch.view(2));
  b.Update(batch.view(2));
  for (int i = 0; i < 8; ++i) EXPECT_EQ(a.last_targets()[i], b.last_targets()[i]);
  // With a clip, the noise changes the targets, the same way for the same seed.
  Td3Config noisy = SmallConfig();
  noisy.target_noise = 0.2f;
  noisy.target_noise_clip = 0.5f;
  Td3 c(spec, noisy), d(spec, noisy);
  c.Update(batch.view(2));
  d.Update(batch.view(2));
  EXPECT_NE(c.last_targets(), a.last_targets());
  EXPECT_EQ(c.last_targets(), d.last_targets());
}

// The actor and the targets change on every policy_delay-th update only; the critics on every
// update; the targets by Polyak averaging.
TEST(Td3Test, DelaysActorAndTargetUpdatesAndAveragesTheTargets) {
  const envs::EnvSpec spec = SmallSpec();
  Td3Config c = SmallConfig();
  c.policy_delay = 3;
  c.tau = 0.1f;
  Td3 td3(spec, c);
  std::mt19937 rng(3);
  for (int u = 1; u <= 6; ++u) {
    const std::vector<float> actor = Flat(td3.actor());
    const std::vector<float> critic = Flat(td3.critic(0));
    const std::vector<float> actor_target = Flat(td3.actor_target());
    const std::vector<float> critic_target = Flat(td3.critic_target(1));
    td3.Update(RandomBatch(spec, 16, &rng).view(2));
    EXPECT_EQ(td3.updates(), u);
    EXPECT_NE(Flat(td3.critic(0)), critic) << "update " << u;
    const bool delayed = u % 3 == 0;
    EXPECT_EQ(td3.actor_updates(), u / 3);
    EXPECT_EQ(Flat(td3.actor()) != actor, delayed) << "update " << u;
    EXPECT_EQ(Flat(td3.actor_target()) != actor_target, delayed) << "update " << u;
    if (!delayed) continue;
    // target' = tau * online' + (1 - tau) * target, parameter by parameter.
    const std::vector<float> online = Flat(td3.actor());
    const std::vector<float> after = Flat(td3.actor_target());
    for (size_t k = 0; k < after.size(); ++k) {
      ASSERT_NEAR(after[k], 0.1f * online[k] + 0.9f * actor_target[k], 1e-6f) << k;
    }
    const std::vector<float> q2 = Flat(td3.critic(1));
    const std::vector<float> q2_after = Flat(td3.critic_target(1));
    for (size_t k = 0; k < q2_after.size(); ++k) {
      ASSERT_NEAR(q2_after[k], 0.1f * q2[k] + 0.9f * critic_target[k], 1e-6f) << k;
    }
  }
}

// SetLearningRateScale: Adam's steps are proportional to the step size, so from the same start
// and batch a critic scaled by 0.5 moves half as far; scaled by 0 nothing moves.
TEST(Td3Test, LearningRateScaleScalesTheSteps) {
  const envs::EnvSpec spec = SmallSpec();
  Td3Config c = SmallConfig();
  c.policy_delay = 1;
  Td3 full(spec, c);
  Td3 half(spec, c);
  Td3 none(spec, c);
  half.SetLearningRateScale(0.5f);
  none.SetLearningRateScale(0.0f);
  std::mt19937 rng(5);
  const OwnedBatch batch = RandomBatch(spec, 16, &rng);
  const std::vector<float> start_critic = Flat(full.critic(1));
  const std::vector<float> start_actor = Flat(full.actor());
  for (Td3* td3 : {&full, &half, &none}) td3->Update(batch.view(2));
  EXPECT_EQ(Flat(none.critic(1)), start_critic);
  EXPECT_EQ(Flat(none.actor()), start_actor);
  const std::vector<float> after_full = Flat(full.critic(1));
  const std::vector<float> after_half = Flat(half.critic(1));
  ASSERT_NE(after_full, start_critic);
  for (size_t k = 0; k < start_critic.size(); ++k) {
    const float step = after_full[k] - start_critic[k];
    ASSERT_NEAR(after_half[k] - start_critic[k], 0.5f * step, 1e-7f + 1e-3f * std::abs(step)) << k;
  }
  EXPECT_NE(Flat(half.actor()), start_actor);
  // Back to 1: the configured step sizes again.
  half.SetLearningRateScale(1.0f);
  none.SetLearningRateScale(1.0f);
  none.Update(batch.view(2));
  EXPECT_NE(Flat(none.critic(1)), start_critic);
}

// The actor's gradient: d(-mean_i Q1(s_i, mu(s_i)))/d(theta), through the critic's action input,
// against central finite differences of that loss in the actor's parameters.
TEST(Td3Test, TheActorsGradientThroughTheCriticMatchesFiniteDifferences) {
  const envs::EnvSpec spec = SmallSpec();
  Td3 td3(spec, SmallConfig());
  std::mt19937 rng(4);
  for (int k = 0; k < 3; ++k) td3.Update(RandomBatch(spec, 16, &rng).view(2));
  const OwnedBatch b = RandomBatch(spec, 6, &rng);
  nn::Sequential actor = td3.actor();
  nn::ActionValueNet q1 = td3.critic(0);
  const auto loss = [&]() {
    const nn::Matrix mu = actor.Forward(b.obs);
    return -static_cast<double>(q1.Forward(b.obs, mu).mean());
  };
  actor.ZeroGrad();
  q1.ZeroGrad();
  const nn::Matrix& mu = actor.Forward(b.obs);
  q1.Forward(b.obs, mu);
  nn::Matrix grad_q = nn::Matrix::Constant(1, 6, -1.0f / 6.0f);
  q1.BackwardParams(grad_q);
  const nn::Matrix grad_action = q1.grad_action();
  actor.BackwardParams(grad_action);
  int checked = 0;
  for (nn::Param& p : actor.Params()) {
    for (Eigen::Index k = 0; k < p.value->size(); k += 3) {
      float& w = p.value->data()[k];
      const float saved = w;
      const float eps = 1e-2f;
      w = saved + eps;
      const double up = loss();
      w = saved - eps;
      const double down = loss();
      w = saved;
      const double numeric = (up - down) / (2 * eps);
      const double analytic = p.grad->data()[k];
      EXPECT_NEAR(analytic, numeric, 2e-3 + 2e-2 * std::abs(numeric)) << p.name << "[" << k << "]";
      ++checked;
    }
  }
  EXPECT_GT(checked, 10);
}

// A one-step bandit: reward -(a - 0.3)^2, no bootstrapping. The critic learns the parabola and the
// actor climbs it to a = 0.3.
TEST(Td3Test, LearnsTheBestActionOfABandit) {
  envs::EnvSpec spec = envs::PendulumSpec();
  spec.observation_size = 1;
  spec.action_low = {-1.0f};
  spec.action_high = {1.0f};
  Td3Config c;
  c.hidden = {32, 32};
  c.actor_learning_rate = 1e-3f;
  c.critic_learning_rate = 1e-3f;
  c.seed = 5;
  Td3 td3(spec, c);
  std::mt19937 rng(6);
  std::uniform_real_distribution<float> uniform(-1.0f, 1.0f);
  OwnedBatch b;
  b.obs = nn::Matrix::Ones(1, 64);
  b.next_obs = nn::Matrix::Ones(1, 64);
  b.discount.assign(64, 0.0f);
  for (int u = 0; u < 5000; ++u) {
    b.action.clear();
    b.reward.clear();
    for (int i = 0; i < 64; ++i) {
      const float a = uniform(rng);
      b.action.push_back(a);
      b.reward.push_back(-(a - 0.3f) * (a - 0.3f));
    }
    td3.Update(b.view(1));
  }
  const float one = 1.0f;
  const float a = td3.actor().Predict(&one, 1)(0, 0);
  EXPECT_NEAR(a, 0.3f, 0.05f);
}

TEST(Td3Test, RefusesDiscreteEnvsBatchesThatDoNotFitAndBadConfigs) {
  EXPECT_THROW(Td3(envs::CartPoleSpec(), Td3Config{}), std::invalid_argument);
  const envs::EnvSpec spec = SmallSpec();
  Td3 td3(spec, SmallConfig());
  std::mt19937 rng(7);
  OwnedBatch b = RandomBatch(spec, 4, &rng);
  EXPECT_THROW(td3.Update(b.view(1)), std::invalid_argument);  // width 1, the env has 2
  b.action[3] = std::nanf("");
  EXPECT_THROW(td3.Update(b.view(2)), std::invalid_argument);
  EXPECT_EQ(td3.updates(), 0);
  Td3Config c;
  c.policy_delay = 0;
  EXPECT_THROW(c.Validate(), std::invalid_argument);
  c = Td3Config{};
  c.tau = 0;
  EXPECT_THROW(c.Validate(), std::invalid_argument);
  c = Td3Config{};
  c.network = "resnet";
  EXPECT_THROW(c.Validate(), std::invalid_argument);
  c = Td3Config{};
  c.network = "car";  // needs 4 x 84 x 84 observations
  EXPECT_THROW(Td3(spec, c), std::invalid_argument);
}

TEST(Td3Test, BuildsTheArticlesCarRacingNetworks) {
  envs::EnvSpec spec = envs::CarRacingSpec(true);
  spec.observation_size = 4 * 84 * 84;
  spec.frame_stack = 4;
  spec.frame_height = spec.frame_width = 84;
  Td3Config c;
  c.network = "car";
  Td3 td3(spec, c);
  EXPECT_EQ(td3.actor().InputSize(), 4 * 84 * 84);
  EXPECT_EQ(td3.actor().OutputSize(), 3);
  EXPECT_NE(td3.actor().Architecture().find("bounded(3,-1,1,0,1,0,1)"), std::string::npos);
  std::mt19937 rng(8);
  OwnedBatch b = RandomBatch(spec, 4, &rng);
  b.obs = b.obs.cwiseAbs().cwiseMin(1.0f);
  b.next_obs = b.next_obs.cwiseAbs().cwiseMin(1.0f);
  EXPECT_NO_THROW(td3.Update(b.view(3)));
  EXPECT_NO_THROW(td3.Update(b.view(3)));
  EXPECT_EQ(td3.actor_updates(), 1);
}

envs::EnvSpec CarPixelSpec() {
  envs::EnvSpec spec = envs::CarRacingSpec(true);
  spec.observation_size = 4 * 84 * 84;
  spec.frame_stack = 4;
  spec.frame_height = spec.frame_width = 84;
  return spec;
}

TEST(Td3Test, SharedEncoderPolicyIsTheEncoderFollowedByTheActorHead) {
  const envs::EnvSpec spec = CarPixelSpec();
  Td3Config c;
  c.network = "drq";
  c.hidden = {64};
  Td3 td3(spec, c);
  ASSERT_TRUE(td3.shared_encoder());
  nn::Sequential& policy = td3.policy();
  EXPECT_EQ(policy.InputSize(), 4 * 84 * 84);
  EXPECT_EQ(policy.OutputSize(), 3);
  EXPECT_EQ(td3.actor().InputSize(), 512);
  std::vector<float> joined = Flat(td3.encoder());
  const std::vector<float> head = Flat(td3.actor());
  joined.insert(joined.end(), head.begin(), head.end());
  EXPECT_EQ(Flat(policy), joined);
  // Same actions as the head on the encoder's features.
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> unit(0, 1);
  nn::Matrix x(4 * 84 * 84, 2);
  for (Eigen::Index k = 0; k < x.size(); ++k) x.data()[k] = unit(rng);
  const nn::Matrix direct = policy.Forward(x);
  const nn::Matrix features = td3.encoder().Forward(x);
  const nn::Matrix via_head = td3.actor().Forward(features);
  EXPECT_TRUE(direct.isApprox(via_head, 1e-5f));
  EXPECT_NE(td3.Describe().find("one encoder trained by the critics"), std::string::npos);
}

TEST(Td3Test, SharedEncoderLearnsFromTheCriticsOnly) {
  const envs::EnvSpec spec = CarPixelSpec();
  std::mt19937 rng(8);
  OwnedBatch b = RandomBatch(spec, 4, &rng);
  b.obs = b.obs.cwiseAbs().cwiseMin(1.0f);
  b.next_obs = b.next_obs.cwiseAbs().cwiseMin(1.0f);
  // Critic learning rate far too small to move anything in float: only the actor's step could.
  Td3Config frozen;
  frozen.network = "drq";
  frozen.hidden = {32};
  frozen.policy_delay = 1;
  frozen.critic_learning_rate = 1e-30f;
  frozen.actor_learning_rate = 1e-2f;
  Td3 a(spec, frozen);
  const std::vector<float> encoder_before = Flat(a.encoder());
  const std::vector<float> head_before = Flat(a.actor());
  a.Update(b.view(3));
  EXPECT_EQ(a.actor_updates(), 1);
  EXPECT_EQ(Flat(a.encoder()), encoder_before);  // The actor's loss does not reach it.
  EXPECT_NE(Flat(a.actor()), head_before);
  // With a real critic learning rate the encoder moves.
  Td3Config learning = frozen;
  learning.critic_learning_rate = 1e-3f;
  Td3 c(spec, learning);
  const std::vector<float> before = Flat(c.encoder());
  c.Update(b.view(3));
  EXPECT_NE(Flat(c.encoder()), before);
  // The broadcast policy follows both parts.
  std::vector<float> joined = Flat(c.encoder());
  const std::vector<float> head = Flat(c.actor());
  joined.insert(joined.end(), head.begin(), head.end());
  EXPECT_EQ(Flat(c.policy()), joined);
}

// encoder-precision bf16 beside precision fp32: the encoder computes as the whole network does in
// bf16, the actor head as in fp32; refused for a network without a shared encoder and for a name
// that is no precision.
TEST(Td3Test, SharedEncoderCanComputeInItsOwnPrecision) {
  const envs::EnvSpec spec = CarPixelSpec();
  Td3Config c;
  c.network = "drq";
  c.hidden = {32};
  c.encoder_precision = "bf16";
  Td3 mixed(spec, c);
  EXPECT_EQ(mixed.encoder().precision(), nn::Precision::kBf16);
  EXPECT_EQ(mixed.actor().precision(), nn::Precision::kFp32);
  c.encoder_precision.clear();
  c.precision = nn::Precision::kBf16;
  Td3 bf16(spec, c);
  c.precision = nn::Precision::kFp32;
  Td3 fp32(spec, c);
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> unit(0, 1);
  nn::Matrix x(4 * 84 * 84, 2);
  for (Eigen::Index k = 0; k < x.size(); ++k) x.data()[k] = unit(rng);
  const nn::Matrix features = mixed.encoder().Forward(x);
  EXPECT_TRUE((features.array() == bf16.encoder().Forward(x).array()).all());
  EXPECT_FALSE((features.array() == fp32.encoder().Forward(x).array()).all());

  c.encoder_precision = "fp16";
  EXPECT_THROW(c.Validate(), std::invalid_argument);
  c.encoder_precision = "bf16";
  c.network = "mlp";
  EXPECT_THROW(c.Validate(), std::invalid_argument);
}

TEST(Td3Test, SharedEncoderNeedsCarRacingStacks) {
  envs::EnvSpec spec = CarPixelSpec();
  spec.observation_size = 4 * 42 * 42;
  Td3Config c;
  c.network = "drq";
  EXPECT_THROW(Td3(spec, c), std::invalid_argument);
  c.network = "resnet";
  EXPECT_THROW(c.Validate(), std::invalid_argument);
}

// SaveState then LoadState into a fresh TD3 (another seed): the next updates are bit-identical,
// with the shared encoder too.
TEST(Td3Test, RestoredStateContinuesBitForBit) {
  for (const std::string network : {"mlp", "drq"}) {
    SCOPED_TRACE(network);
    const envs::EnvSpec spec = network == "drq" ? CarPixelSpec() : envs::LunarLanderSpec(true);
    Td3Config c;
    c.network = network;
    c.hidden = {16, 16};
    c.seed = 1;
    std::mt19937 rng(5);
    OwnedBatch b = RandomBatch(spec, 4, &rng);
    b.obs = b.obs.cwiseAbs().cwiseMin(1.0f);
    b.next_obs = b.next_obs.cwiseAbs().cwiseMin(1.0f);
    const int width = spec.action_width();
    Td3 a(spec, c);
    for (int k = 0; k < 3; ++k) a.Update(b.view(width));
    StateFile state("td3");
    a.SaveState(&state);
    c.seed = 99;
    Td3 restored(spec, c);
    restored.LoadState(state);
    EXPECT_EQ(restored.updates(), 3);
    EXPECT_EQ(restored.actor_updates(), 1);
    for (int k = 0; k < 3; ++k) {
      const UpdateResult ra = a.Update(b.view(width));
      const UpdateResult rb = restored.Update(b.view(width));
      EXPECT_EQ(ra.loss, rb.loss);
    }
    EXPECT_EQ(Flat(a.policy()), Flat(restored.policy()));
    // Another architecture is refused.
    Td3Config other = c;
    other.hidden = {8, 8};
    Td3 wrong(spec, other);
    EXPECT_THROW(wrong.LoadState(state), std::runtime_error);
  }
}

TEST(Td3Test, TheTwinCriticsSideBySideOnTwoThreadsUpdateAsOnOne) {
  // The two critics' passes run as two tasks of the nn pool: on two threads every loss, critic
  // and actor equal those on one thread bit for bit (a head's products computed whole in a task
  // are the same products), and the pool is used (two sections an update).
  const envs::EnvSpec spec = envs::LunarLanderSpec(true);
  Td3Config c;
  c.hidden = {64, 64};
  c.seed = 1;
  c.target_noise = 0.2f;
  std::mt19937 rng(5);
  const OwnedBatch b = RandomBatch(spec, 256, &rng);
  const int width = spec.action_width();
  std::vector<float> losses[2], actor[2], critic[2];
  for (int threads : {1, 2}) {
    nn::SetNumThreads(threads);
    const int64_t sections = nn::internal::ParallelSections();
    Td3 td3(spec, c);
    for (int k = 0; k < 4; ++k) losses[threads - 1].push_back(td3.Update(b.view(width)).loss);
    actor[threads - 1] = Flat(td3.actor());
    critic[threads - 1] = Flat(td3.critic(1));
    if (threads == 2) {
      EXPECT_GE(nn::internal::ParallelSections() - sections, 8);
    }
  }
  nn::SetNumThreads(1);
  EXPECT_EQ(losses[0], losses[1]);
  EXPECT_EQ(actor[0], actor[1]);
  EXPECT_EQ(critic[0], critic[1]);
}

}  // namespace
}  // namespace rl::learner
