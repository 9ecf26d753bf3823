#include "envs/box2d/lunar_lander_heuristic.h"

#include <array>
#include <cstdint>
#include <cstdio>
#include <random>
#include <stdexcept>
#include <string>

#include <gtest/gtest.h>

#include "envs/registry.h"

namespace rl::envs {
namespace {

// Scores of a policy over seeds 0 .. episodes - 1 of a registered env.
struct Scores {
  double mean_return = 0;
  int landed = 0;     // Episodes ending with the +100 of coming to rest.
  int truncated = 0;  // Episodes cut at 1000 steps.
};

template <typename Policy>
Scores Evaluate(const std::string& id, int episodes, Policy policy) {
  auto env = MakeEnv(id);
  Scores scores;
  for (int e = 0; e < episodes; ++e) {
    env->Reset(static_cast<uint64_t>(e));
    double episode_return = 0;
    StepResult r;
    do {
      r = policy(*env);
      episode_return += r.reward;
    } while (!r.terminated && !r.truncated);
    scores.mean_return += episode_return / episodes;
    scores.landed += r.terminated && r.reward == 100.0;
    scores.truncated += r.truncated;
  }
  std::printf("%s over %d episodes: mean return %.2f, %d landed, %d truncated\n", id.c_str(),
              episodes, scores.mean_return, scores.landed, scores.truncated);
  return scores;
}

TEST(LunarLanderHeuristicTest, ErrorsFollowThePdRules) {
  // angle target 0.5 * 0.2 + 0.1 = 0.2, hover target 0.55 * 0.2 = 0.11;
  // angle_todo = (0.2 - 0.05) / 2 - 0.1 = -0.025, hover_todo = (0.11 - 0.5) / 2 + 0.1 = -0.095.
  const std::array<float, 8> obs = {0.2f, 0.5f, 0.1f, -0.2f, 0.05f, 0.1f, 0, 0};
  const LunarLanderHeuristicErrors e = ComputeLunarLanderHeuristicErrors(obs);
  EXPECT_NEAR(e.angle_todo, -0.025, 1e-7);
  EXPECT_NEAR(e.hover_todo, -0.095, 1e-7);
  EXPECT_EQ(LunarLanderHeuristicAction(obs), 0);  // Both errors inside the dead band.

  // The angle target is clipped to 0.4: here 0.5 + 1 would be 1.5.
  const std::array<float, 8> far = {1.0f, 1.0f, 1.0f, 0.0f, 0.0f, 0.0f, 0, 0};
  EXPECT_NEAR(ComputeLunarLanderHeuristicErrors(far).angle_todo, 0.2, 1e-7);
  // hover target 0.55, hover_todo = (0.55 - 1) / 2 = -0.225; angle_todo 0.2 > 0.05: left engine.
  EXPECT_NEAR(ComputeLunarLanderHeuristicErrors(far).hover_todo, -0.225, 1e-7);
  EXPECT_EQ(LunarLanderHeuristicAction(far), 1);

  // With a leg down only the fall is damped.
  const std::array<float, 8> touching = {0.5f, 0.0f, 0.3f, -0.4f, 0.3f, 0.2f, 0, 1};
  const LunarLanderHeuristicErrors t = ComputeLunarLanderHeuristicErrors(touching);
  EXPECT_EQ(t.angle_todo, 0.0);
  EXPECT_NEAR(t.hover_todo, 0.2, 1e-7);
  EXPECT_EQ(LunarLanderHeuristicAction(touching), 2);

  EXPECT_THROW(ComputeLunarLanderHeuristicErrors(std::array<float, 4>{}), std::invalid_argument);
}

TEST(LunarLanderHeuristicTest, DiscreteActionsPickTheFirstMatchingRule) {
  // Falling fast near the centre: hover_todo = (0 - 0.5) / 2 + 0.5 = 0.25 > |angle_todo|.
  EXPECT_EQ(LunarLanderHeuristicAction(std::array<float, 8>{0, 0.5f, 0, -1.0f, 0, 0, 0, 0}), 2);
  // Tilted left (positive angle) and level: angle_todo = -0.3 / 2 = -0.15: right engine.
  EXPECT_EQ(LunarLanderHeuristicAction(std::array<float, 8>{0, 0.5f, 0, 0, 0.3f, 0, 0, 0}), 3);
  // Tilted right: left engine.
  EXPECT_EQ(LunarLanderHeuristicAction(std::array<float, 8>{0, 0.5f, 0, 0, -0.3f, 0, 0, 0}), 1);
}

TEST(LunarLanderHeuristicTest, ContinuousActionsAreScaledAndClipped) {
  // hover_todo = -0.095, angle_todo = -0.025 (see above): [-2.9 -> -1, 0.5].
  const std::array<float, 2> a = LunarLanderHeuristicContinuousAction(
      std::array<float, 8>{0.2f, 0.5f, 0.1f, -0.2f, 0.05f, 0.1f, 0, 0});
  EXPECT_EQ(a[0], -1.0f);
  EXPECT_NEAR(a[1], 0.5f, 1e-5f);
  // hover_todo = 0.25: 0.25 * 20 - 1 = 4 -> 1; angle_todo = -0.15: 3 -> 1.
  const std::array<float, 2> b =
      LunarLanderHeuristicContinuousAction(std::array<float, 8>{0, 0.5f, 0, -1.0f, 0.3f, 0, 0, 0});
  EXPECT_EQ(b[0], 1.0f);
  EXPECT_EQ(b[1], 1.0f);
}

TEST(LunarLanderHeuristicTest, DiscreteHeuristicLandsMostEpisodesAndAveragesAbove200) {
  // The reference quotes 236.90 +- 105.83 over 1000 episodes.
  const Scores s = Evaluate("LunarLander-v3", 100, [](Env& env) {
    return env.Step(DiscreteAction(LunarLanderHeuristicAction(env.observation())));
  });
  EXPECT_GT(s.mean_return, 200.0);
  EXPECT_GE(s.landed, 80);
}

TEST(LunarLanderHeuristicTest, ContinuousHeuristicLandsAlmostAlwaysAndAveragesAbove200) {
  // The reference quotes 283.87 +- 18.88 over 1000 episodes.
  const Scores s = Evaluate("LunarLanderContinuous-v3", 100, [](Env& env) {
    return env.Step(LunarLanderHeuristicContinuousAction(env.observation()));
  });
  EXPECT_GT(s.mean_return, 250.0);
  EXPECT_GE(s.landed, 95);
}

TEST(LunarLanderHeuristicTest, UniformRandomPolicyScoresBetweenMinus250AndMinus50) {
  std::mt19937_64 rng(2024);
  const Scores s = Evaluate("LunarLander-v3", 100, [&rng](Env& env) {
    return env.Step(DiscreteAction(static_cast<int>(rng() >> 62)));
  });
  EXPECT_GT(s.mean_return, -250.0);
  EXPECT_LT(s.mean_return, -50.0);
  EXPECT_EQ(s.truncated, 0);  // A random lander never lasts 1000 steps.
}

}  // namespace
}  // namespace rl::envs
