#include "envs/time_limit.h"

#include <array>
#include <cmath>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <stdexcept>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "envs/cartpole.h"
#include "envs/registry.h"

namespace rl::envs {
namespace {

// A scripted env: terminates on step `terminate_at` of an episode (never if 0) and records calls.
class ScriptedEnv : public Env {
 public:
  explicit ScriptedEnv(int terminate_at)
      : Env(EnvSpec{"Scripted-v0", 1, 1, 1000, 5.0}), terminate_at_(terminate_at) {}
  std::span<const float> observation() const override { return observation_; }
  void Render(std::vector<uint8_t>* rgb, int* width, int* height) const override {
    rgb->assign(3, 7);
    *width = 1;
    *height = 1;
  }

  int steps = 0;
  int resets = 0;
  uint64_t last_seed = 0;

 private:
  void OnReset(std::optional<uint64_t> seed) override {
    if (seed.has_value()) last_seed = *seed;
    steps = 0;
    ++resets;
  }
  StepResult OnStep(std::span<const float> /*action*/) override {
    ++steps;
    return StepResult{.reward = 2.0, .terminated = steps == terminate_at_, .truncated = false};
  }

  std::array<float, 1> observation_{};
  int terminate_at_;
};

// Bang-bang state feedback that keeps the pole up and the cart near the centre indefinitely.
int BalancingAction(std::span<const float> obs) {
  const double u = 1.0 * obs[0] + 1.0 * obs[1] + 10.0 * obs[2] + 1.0 * obs[3];
  return u > 0 ? 1 : 0;
}

TEST(TimeLimitTest, TruncatesOnTheStepThatReachesTheLimitAndNotBefore) {
  auto inner = std::make_unique<ScriptedEnv>(/*terminate_at=*/0);
  TimeLimit env(std::move(inner), 3);
  env.Reset(5);
  EXPECT_EQ(env.elapsed_steps(), 0);
  EXPECT_FALSE(env.Step(DiscreteAction(0)).truncated);
  EXPECT_FALSE(env.Step(DiscreteAction(0)).truncated);
  const StepResult third = env.Step(DiscreteAction(0));
  EXPECT_TRUE(third.truncated);
  EXPECT_FALSE(third.terminated);
  EXPECT_EQ(third.reward, 2.0);
  EXPECT_EQ(env.elapsed_steps(), 3);
  // Stepping on keeps counting and keeps truncating, as Gymnasium does.
  EXPECT_TRUE(env.Step(DiscreteAction(0)).truncated);
  EXPECT_EQ(env.elapsed_steps(), 4);
}

TEST(TimeLimitTest, ResetRestartsTheCountAndForwardsTheSeed) {
  auto inner = std::make_unique<ScriptedEnv>(0);
  ScriptedEnv* scripted = inner.get();
  TimeLimit env(std::move(inner), 2);
  env.Reset(99);
  EXPECT_EQ(scripted->last_seed, 99u);
  env.Step(DiscreteAction(0));
  env.Step(DiscreteAction(0));
  env.Reset();
  EXPECT_EQ(scripted->resets, 2);
  EXPECT_EQ(env.elapsed_steps(), 0);
  EXPECT_FALSE(env.Step(DiscreteAction(0)).truncated);
  EXPECT_TRUE(env.Step(DiscreteAction(0)).truncated);
}

TEST(TimeLimitTest, TerminatedPassesThroughAndCanCoincideWithTruncated) {
  TimeLimit early(std::make_unique<ScriptedEnv>(2), 5);
  early.Reset(0);
  early.Step(DiscreteAction(0));
  const StepResult ended = early.Step(DiscreteAction(0));
  EXPECT_TRUE(ended.terminated);
  EXPECT_FALSE(ended.truncated);

  TimeLimit both(std::make_unique<ScriptedEnv>(4), 4);
  both.Reset(0);
  for (int t = 0; t < 3; ++t) both.Step(DiscreteAction(0));
  const StepResult last = both.Step(DiscreteAction(0));
  EXPECT_TRUE(last.terminated);
  EXPECT_TRUE(last.truncated);
}

TEST(TimeLimitTest, SpecCarriesTheLimitAndForwardsEverythingElse) {
  TimeLimit env(std::make_unique<ScriptedEnv>(0), 17);
  EXPECT_EQ(env.spec().id, "Scripted-v0");
  EXPECT_EQ(env.spec().max_episode_steps, 17);
  EXPECT_EQ(env.max_episode_steps(), 17);
  EXPECT_EQ(env.spec().reward_threshold, 5.0);
  EXPECT_EQ(env.observation().size(), 1u);
  std::vector<uint8_t> rgb;
  int width = 0;
  int height = 0;
  env.Render(&rgb, &width, &height);
  EXPECT_EQ(width, 1);
  EXPECT_EQ(rgb, (std::vector<uint8_t>{7, 7, 7}));
  EXPECT_NE(dynamic_cast<ScriptedEnv*>(&env.wrapped_env()), nullptr);
}

TEST(TimeLimitTest, InvalidActionThrowsWithoutCountingAStep) {
  TimeLimit env(std::make_unique<ScriptedEnv>(0), 3);
  env.Reset(0);
  EXPECT_THROW(env.Step(DiscreteAction(1)), std::invalid_argument);
  EXPECT_EQ(env.elapsed_steps(), 0);
}

// A continuous scripted env: one float action, which must be finite; never terminates.
class ScriptedContinuousEnv : public Env {
 public:
  ScriptedContinuousEnv()
      : Env(EnvSpec{.id = "ScriptedContinuous-v0",
                    .observation_size = 1,
                    .num_actions = 0,
                    .max_episode_steps = 1000,
                    .reward_threshold = 0,
                    .action_dim = 1,
                    .action_low = {-2},
                    .action_high = {2}}) {}
  std::span<const float> observation() const override { return observation_; }
  void Render(std::vector<uint8_t>* rgb, int* width, int* height) const override {
    rgb->assign(3, 0);
    *width = 1;
    *height = 1;
  }

  float last_action = 0;

 private:
  void OnReset(std::optional<uint64_t> /*seed*/) override {}
  StepResult OnStep(std::span<const float> action) override {
    last_action = action[0];
    return StepResult{.reward = action[0]};
  }

  std::array<float, 1> observation_{};
};

TEST(TimeLimitTest, ForwardsContinuousStepsAndCountsThem) {
  auto inner = std::make_unique<ScriptedContinuousEnv>();
  ScriptedContinuousEnv* scripted = inner.get();
  TimeLimit env(std::move(inner), 2);
  EXPECT_EQ(env.spec().action_dim, 1);
  EXPECT_EQ(env.spec().action_low, std::vector<float>{-2.0f});
  EXPECT_EQ(env.spec().action_high, std::vector<float>{2.0f});
  env.Reset(0);
  const StepResult first = env.Step(std::array<float, 1>{1.5f});
  EXPECT_EQ(first.reward, 1.5);
  EXPECT_EQ(scripted->last_action, 1.5f);
  EXPECT_FALSE(first.truncated);
  // A rejected action is not counted.
  EXPECT_THROW(env.Step(std::array<float, 2>{0, 0}), std::invalid_argument);
  EXPECT_THROW(env.Step(std::array<float, 1>{NAN}), std::invalid_argument);
  EXPECT_EQ(env.elapsed_steps(), 1);
  EXPECT_TRUE(env.Step(std::array<float, 1>{0}).truncated);
  EXPECT_EQ(env.elapsed_steps(), 2);
}

TEST(TimeLimitTest, AContinuousActionOnADiscreteEnvThrowsWithoutCounting) {
  TimeLimit env(std::make_unique<ScriptedEnv>(0), 3);
  env.Reset(0);
  EXPECT_THROW(env.Step(std::array<float, 2>{0, 0}), std::invalid_argument);
  EXPECT_THROW(env.Step(std::array<float, 1>{0.5f}), std::invalid_argument);
  EXPECT_EQ(env.elapsed_steps(), 0);
}

TEST(TimeLimitTest, RejectsANullEnvAndANonPositiveLimit) {
  EXPECT_THROW(TimeLimit(nullptr, 10), std::invalid_argument);
  EXPECT_THROW(TimeLimit(std::make_unique<ScriptedEnv>(0), 0), std::invalid_argument);
  EXPECT_THROW(TimeLimit(std::make_unique<ScriptedEnv>(0), -5), std::invalid_argument);
}

TEST(TimeLimitTest, BalancedCartPoleIsTruncatedAtExactlyStep500) {
  auto env = MakeEnv("CartPole-v1");
  for (uint64_t seed : {0, 1, 2}) {
    env->Reset(seed);
    double episode_return = 0;
    for (int t = 1; t <= 499; ++t) {
      const StepResult r = env->Step(DiscreteAction(BalancingAction(env->observation())));
      episode_return += r.reward;
      ASSERT_FALSE(r.terminated) << "seed " << seed << " step " << t;
      ASSERT_FALSE(r.truncated) << "seed " << seed << " step " << t;
    }
    const StepResult last = env->Step(DiscreteAction(BalancingAction(env->observation())));
    episode_return += last.reward;
    EXPECT_TRUE(last.truncated) << "seed " << seed;
    EXPECT_FALSE(last.terminated) << "seed " << seed;
    EXPECT_EQ(episode_return, 500.0);
    EXPECT_GE(episode_return, env->spec().reward_threshold);
    EXPECT_EQ(dynamic_cast<TimeLimit&>(*env).elapsed_steps(), 500);
  }
}

TEST(TimeLimitTest, CartPoleFallingOnStep500IsTerminatedAndTruncated) {
  auto env = MakeEnv("CartPole-v1");
  auto& cartpole = dynamic_cast<CartPole&>(dynamic_cast<TimeLimit&>(*env).wrapped_env());
  env->Reset(3);
  for (int t = 1; t <= 499; ++t) {
    ASSERT_FALSE(env->Step(DiscreteAction(BalancingAction(env->observation()))).truncated);
  }
  // Put the cart past the edge with zero velocity so the 500th step ends the episode.
  cartpole.set_state({2.5, 0, 0, 0});
  const StepResult last = env->Step(DiscreteAction(0));
  EXPECT_TRUE(last.terminated);
  EXPECT_TRUE(last.truncated);
  EXPECT_EQ(last.reward, 1.0);
}

}  // namespace
}  // namespace rl::envs
