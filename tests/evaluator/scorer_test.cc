#include "evaluator/scorer.h"

#include <cmath>
#include <functional>
#include <memory>
#include <optional>
#include <random>
#include <span>
#include <stdexcept>
#include <vector>

#include <gtest/gtest.h>

#include "envs/registry.h"
#include "envs/specs.h"
#include "nn/sequential.h"

namespace rl::evaluator {
namespace {

constexpr char kEnv[] = "CartPole-v1";

// A CartPole network whose output is its last layer's bias: every weight zero, so the greedy
// action is always `action`.
nn::Sequential AlwaysChooses(int action) {
  std::mt19937 rng(1);
  nn::Sequential net = nn::MakeMlp(4, {16}, 2, &rng);
  std::vector<float> flat(static_cast<size_t>(net.NumParams()), 0.0f);
  // Parameters are layer by layer, weight then bias: the last two floats are the output bias.
  flat[flat.size() - 2 + static_cast<size_t>(action)] = 1.0f;
  net.SetFlat(flat.data(), flat.size());
  return net;
}

// A policy played by a function of the observation (a stand-in for a network, to count calls
// and script behaviour); `value`, when set, gives the estimate of the action chosen.
class ScriptedPolicy : public actor::Policy {
 public:
  using ActionFn = std::function<float(std::span<const float>)>;
  using ValueFn = std::function<double(std::span<const float>)>;
  explicit ScriptedPolicy(ActionFn act, ValueFn value = {})
      : Policy(envs::LookupSpec(kEnv), actor::ExplorationConfig{}, 0, 1, 1),
        act_(std::move(act)),
        value_fn_(std::move(value)) {}
  void Act(std::span<const float> obs, int64_t /*step*/, std::span<float> action) override {
    ++calls;
    action[0] = act_(obs);
    if (value_fn_) value_ = value_fn_(obs);
  }
  std::optional<double> last_value() const override { return value_; }
  double exploration(int64_t /*step*/) const override { return 0.0; }
  int calls = 0;

 private:
  ActionFn act_;
  ValueFn value_fn_;
  std::optional<double> value_;
};

// Plays the episodes first_seed .. first_seed + episodes - 1 with a fixed action.
std::vector<double> PlayByHand(int action, int episodes, uint64_t first_seed) {
  auto env = envs::MakeEnv(kEnv);
  std::vector<double> returns;
  for (int i = 0; i < episodes; ++i) {
    env->Reset(first_seed + static_cast<uint64_t>(i));
    double total = 0;
    for (;;) {
      const envs::StepResult r = env->Step(rl::envs::DiscreteAction(action));
      total += r.reward;
      if (r.terminated || r.truncated) break;
    }
    returns.push_back(total);
  }
  return returns;
}

TEST(ScorerTest, AConstantActionNetworkScoresAsTheSameEpisodesPlayedByHand) {
  nn::Sequential net = AlwaysChooses(1);
  const std::vector<float> obs = {0.01f, -0.02f, 0.03f, 0.04f};
  ASSERT_EQ(net.Argmax(obs.data(), 4), 1);

  const EvalScore score = ScorePolicy(&net, kEnv, 20, /*epsilon=*/0.0, kDefaultEvalSeedBase);
  const std::vector<double> by_hand = PlayByHand(1, 20, kDefaultEvalSeedBase);
  EXPECT_EQ(score.returns, by_hand);
  double sum = 0;
  for (double r : by_hand) sum += r;
  EXPECT_DOUBLE_EQ(score.mean, sum / 20.0);
  // Pushing the cart one way topples the pole within a few steps.
  EXPECT_LT(score.mean, 20.0);
  EXPECT_GT(score.mean, 5.0);
  EXPECT_LE(score.max, 20.0);
  EXPECT_TRUE(score.action_mean.empty()) << "a discrete env's actions have no mean";
}

TEST(ScorerTest, TheSameSeedsGiveTheSameScore) {
  std::mt19937 rng(7);
  nn::Sequential net = nn::MakeMlp(4, {32}, 2, &rng);
  for (double epsilon : {0.0, 0.05, 0.5}) {
    const EvalScore a = ScorePolicy(&net, kEnv, 10, epsilon, 123);
    const EvalScore b = ScorePolicy(&net, kEnv, 10, epsilon, 123);
    EXPECT_EQ(a.returns, b.returns) << "epsilon " << epsilon;
  }
  // Other seeds give other initial states.
  const EvalScore a = ScorePolicy(&net, kEnv, 10, 0.5, 123);
  const EvalScore c = ScorePolicy(&net, kEnv, 10, 0.5, 456);
  EXPECT_NE(a.returns, c.returns);
}

TEST(ScorerTest, EpisodeIUsesSeedFirstSeedPlusI) {
  nn::Sequential net = AlwaysChooses(0);
  const EvalScore from_10 = ScorePolicy(&net, kEnv, 5, 0.0, 10);
  const EvalScore from_11 = ScorePolicy(&net, kEnv, 4, 0.0, 11);
  ASSERT_EQ(from_10.returns.size(), 5U);
  EXPECT_EQ(std::vector<double>(from_10.returns.begin() + 1, from_10.returns.end()),
            from_11.returns);
}

TEST(ScorerTest, RunsTheRequestedNumberOfEpisodes) {
  nn::Sequential net = AlwaysChooses(0);
  for (int episodes : {1, 7, 30}) {
    const EvalScore s = ScorePolicy(&net, kEnv, episodes, 0.05, 99);
    EXPECT_EQ(s.episodes, episodes);
    EXPECT_EQ(s.returns.size(), static_cast<size_t>(episodes));
  }
}

// The tick comes after every step, not every episode: an evaluator starved of CPU on a busy
// machine would otherwise publish nothing for a whole episode and be taken for a dead one.
TEST(ScorerTest, CallsTheTickOnceAfterEveryStep) {
  int calls = 0;
  ScriptedPolicy policy([](std::span<const float>) { return 0.0f; });
  const EvalScore s = Score(&policy, "CartPole-v1", 4, 1000, kDefaultGamma, [&] {
    ++calls;
    EXPECT_EQ(calls, policy.calls);  // one step since the last call
  });
  // The policy is asked once per step: CartPole rewards 1 per step.
  double steps = 0;
  for (double r : s.returns) steps += r;
  EXPECT_EQ(policy.calls, static_cast<int>(steps));
  EXPECT_EQ(calls, policy.calls);
  // Each episode's length, for the same reason its return.
  ASSERT_EQ(s.steps.size(), s.returns.size());
  for (size_t i = 0; i < s.steps.size(); ++i) EXPECT_EQ(s.steps[i], s.returns[i]) << i;
}

TEST(ScorerTest, EpsilonZeroIsGreedyAndEpsilonOneUniformlyRandom) {
  nn::Sequential net = AlwaysChooses(0);
  EXPECT_EQ(ScorePolicy(&net, kEnv, 20, 0.0, 3).returns, PlayByHand(0, 20, 3));
  // Random pushes balance far longer than always pushing left (about 22 steps against 9).
  const EvalScore random = ScorePolicy(&net, kEnv, 20, 1.0, 3);
  EXPECT_GT(random.mean, ScorePolicy(&net, kEnv, 20, 0.0, 3).mean + 5);
}

TEST(ScorerTest, SummarizeUsesThePopulationStd) {
  const EvalScore s = Summarize({1.0, 2.0, 3.0, 4.0});
  EXPECT_EQ(s.episodes, 4);
  EXPECT_DOUBLE_EQ(s.mean, 2.5);
  EXPECT_DOUBLE_EQ(s.std, std::sqrt(1.25));
  EXPECT_EQ(s.min, 1.0);
  EXPECT_EQ(s.max, 4.0);
}

TEST(ScorerTest, RefusesBadArgumentsAndANetworkThatDoesNotFitTheEnv) {
  nn::Sequential net = AlwaysChooses(0);
  EXPECT_THROW(ScorePolicy(&net, kEnv, 0, 0.05, 1), std::invalid_argument);
  EXPECT_THROW(ScorePolicy(&net, kEnv, 5, 1.5, 1), std::invalid_argument);
  EXPECT_THROW(ScorePolicy(&net, kEnv, 5, -0.1, 1), std::invalid_argument);
  EXPECT_THROW(ScorePolicy(&net, "NoSuchEnv-v0", 5, 0.05, 1), std::invalid_argument);
  std::mt19937 rng(1);
  nn::Sequential wide = nn::MakeMlp(5, {8}, 2, &rng);
  EXPECT_THROW(ScorePolicy(&wide, kEnv, 5, 0.05, 1), std::invalid_argument);
  nn::Sequential three = nn::MakeMlp(4, {8}, 3, &rng);
  EXPECT_THROW(ScorePolicy(&three, kEnv, 5, 0.05, 1), std::invalid_argument);
  ScriptedPolicy out_of_range([](std::span<const float>) { return 2.0f; });
  EXPECT_THROW(Score(&out_of_range, kEnv, 1, 1), std::invalid_argument);
  EXPECT_FALSE(CheckNetworkFitsEnv(three, envs::LookupSpec(kEnv)).empty());
  EXPECT_TRUE(CheckNetworkFitsEnv(net, envs::LookupSpec(kEnv)).empty());
}

TEST(ScorerTest, CorrelationIsPearsonsAndUndefinedForAConstantSeries) {
  const std::vector<double> x = {1, 2, 3, 4};
  EXPECT_NEAR(Correlation(x, std::vector<double>{3, 5, 7, 9}), 1.0, 1e-12);
  EXPECT_NEAR(Correlation(x, std::vector<double>{8, 6, 4, 2}), -1.0, 1e-12);
  EXPECT_NEAR(Correlation(x, std::vector<double>{1, 3, 2, 4}), 0.8, 1e-12);
  EXPECT_TRUE(std::isnan(Correlation(x, std::vector<double>{5, 5, 5, 5})));
  EXPECT_TRUE(std::isnan(Correlation(std::vector<double>{1}, std::vector<double>{2})));
}

TEST(ScorerTest, ComparesTheValueOfEveryActionTakenWithTheDiscountedReturnThatFollowed) {
  // Q = (0, 1) everywhere: action 1 is taken, valued 1, and the pole falls within a few steps
  // (terminated episodes: every step counts).
  nn::Sequential net = AlwaysChooses(1);
  constexpr double kGamma = 0.9;
  const EvalScore score = ScorePolicy(&net, kEnv, 6, /*epsilon=*/0.0, 77, kGamma);
  ASSERT_TRUE(score.values.has_value());
  // CartPole rewards 1 per step: an episode of T steps has the returns (1 - gamma^(T-t)) /
  // (1 - gamma) from its steps t = 0 .. T-1.
  int64_t steps = 0;
  double sum = 0;
  for (double length : PlayByHand(1, 6, 77)) {
    for (int t = 0; t < static_cast<int>(length); ++t) {
      sum += (1 - std::pow(kGamma, length - t)) / (1 - kGamma);
      ++steps;
    }
  }
  EXPECT_EQ(score.values->steps, steps);
  EXPECT_DOUBLE_EQ(score.values->estimate, 1.0);
  EXPECT_NEAR(score.values->actual, sum / static_cast<double>(steps), 1e-9);
  EXPECT_TRUE(std::isnan(score.values->correlation));  // the estimates are constant
  // A policy without values has no calibration.
  ScriptedPolicy greedy([](std::span<const float>) { return 1.0f; });
  EXPECT_FALSE(Score(&greedy, kEnv, 2, 77).values.has_value());
}

TEST(ScorerTest, OfAnEpisodeCutByItsTimeLimitOnlyStepsFarFromTheCutCount) {
  // A balancing controller keeps the pole up for all 500 steps, so every episode is truncated.
  // With gamma 0.99 the unseen rest weighs 0.99^(500 - t): at most 0.01 for t <= 41 (0.99^459 =
  // 0.00995, 0.99^458 = 0.01005), so 42 steps of each episode count. The values are the pole
  // angle's cosine, which tracks nothing of the return here but is not constant.
  ScriptedPolicy balance(
      [](std::span<const float> obs) {
        const float push = obs[2] + 0.5f * obs[3] + 0.01f * obs[0] + 0.1f * obs[1];
        return push > 0 ? 1.0f : 0.0f;
      },
      [](std::span<const float> obs) { return static_cast<double>(std::cos(obs[2])); });
  const EvalScore score = Score(&balance, kEnv, 3, 5, 0.99);
  ASSERT_EQ(score.returns, (std::vector<double>{500, 500, 500}));
  ASSERT_TRUE(score.values.has_value());
  EXPECT_EQ(score.values->steps, 3 * 42);
  // Those steps' returns: (1 - 0.99^(500 - t)) / 0.01 for t = 0 .. 41, between 99.0 and 99.4.
  EXPECT_GT(score.values->actual, 99.0);
  EXPECT_LT(score.values->actual, 99.4);
  EXPECT_GT(score.values->estimate, 0.9);
  EXPECT_LE(score.values->estimate, 1.0);
}

TEST(ScorerTest, RefusesAGammaOutsideTheUnitInterval) {
  nn::Sequential net = AlwaysChooses(0);
  EXPECT_THROW(ScorePolicy(&net, kEnv, 1, 0.0, 1, 1.5), std::invalid_argument);
  EXPECT_THROW(ScorePolicy(&net, kEnv, 1, 0.0, 1, -0.1), std::invalid_argument);
}

// A continuous env is scored with the actor network's action, without noise or epsilon: the
// same returns as the same constant action played by hand, and no value calibration (an actor has
// no value estimates).
constexpr char kLander[] = "LunarLanderContinuous-v3";

// An actor network for kLander whose action is always (0.6, -0.4).
nn::Sequential ConstantLanderActor(std::mt19937* rng) {
  nn::Sequential actor = nn::MakeMlp(8, {4}, 2, rng);
  std::vector<float> flat(static_cast<size_t>(actor.NumParams()), 0.0f);
  flat[flat.size() - 2] = 0.6f;   // main engine
  flat[flat.size() - 1] = -0.4f;  // side engine
  actor.SetFlat(flat.data(), flat.size());
  return actor;
}

// The returns of `episodes` kLander episodes from seed first_seed on, `action` played throughout.
std::vector<double> ConstantActionReturns(std::span<const float> action, int episodes,
                                          uint64_t first_seed) {
  auto env = envs::MakeEnv(kLander);
  std::vector<double> returns;
  for (int i = 0; i < episodes; ++i) {
    env->Reset(first_seed + static_cast<uint64_t>(i));
    double total = 0;
    for (;;) {
      const envs::StepResult r = env->Step(action);
      total += r.reward;
      if (r.terminated || r.truncated) break;
    }
    returns.push_back(total);
  }
  return returns;
}

TEST(ScorerTest, ScoresAContinuousActorWithItsDeterministicAction) {
  std::mt19937 rng(1);
  nn::Sequential actor = ConstantLanderActor(&rng);
  const EvalScore score = ScorePolicy(&actor, kLander, 3, /*epsilon=*/0.05, 40);
  const float action[] = {0.6f, -0.4f};
  EXPECT_EQ(score.returns, ConstantActionReturns(action, 3, 40));
  EXPECT_FALSE(score.values.has_value());
  ASSERT_EQ(score.action_mean.size(), 2U);
  EXPECT_NEAR(score.action_mean[0], 0.6, 1e-6);
  EXPECT_NEAR(score.action_mean[1], -0.4, 1e-6);
  // A Q-network's output size (4 actions) does not fit the 2 action dimensions.
  nn::Sequential q = nn::MakeMlp(8, {4}, 4, &rng);
  EXPECT_THROW(ScorePolicy(&q, kLander, 1, 0.05, 1), std::invalid_argument);
}

// With a sigma, the actor's action gets the actors' Gaussian noise: other returns than the
// deterministic action's, the same ones again for the same seeds, and a negative sigma refused.
TEST(ScorerTest, ScoresAContinuousActorWithTheActorsNoiseWhenGivenASigma) {
  std::mt19937 rng(1);
  nn::Sequential actor = ConstantLanderActor(&rng);
  const EvalScore plain = ScorePolicy(&actor, kLander, 3, 0.05, 40, kDefaultGamma, {}, 0.0);
  const EvalScore noisy = ScorePolicy(&actor, kLander, 3, 0.05, 40, kDefaultGamma, {}, 0.3);
  const EvalScore again = ScorePolicy(&actor, kLander, 3, 0.05, 40, kDefaultGamma, {}, 0.3);
  EXPECT_EQ(plain.returns, ScorePolicy(&actor, kLander, 3, 0.05, 40).returns);
  for (size_t i = 0; i < plain.returns.size(); ++i) {
    EXPECT_NE(noisy.returns[i], plain.returns[i]) << "episode " << i;
  }
  EXPECT_EQ(noisy.returns, again.returns);
  EXPECT_THROW(ScorePolicy(&actor, kLander, 1, 0.05, 1, kDefaultGamma, {}, -0.1),
               std::invalid_argument);
}

// An ensemble acts with the mean of its members' actions: two constant actors give the constant
// action between them, played by hand; a discrete env and no member are refused.
TEST(ScorerTest, AnEnsembleActsWithTheMeanOfItsMembersActions) {
  std::mt19937 rng(1);
  std::vector<nn::Sequential> members = {ConstantLanderActor(&rng), ConstantLanderActor(&rng)};
  std::vector<float> flat;
  members[1].GetFlat(&flat);
  flat[flat.size() - 2] = 0.2f;
  flat[flat.size() - 1] = 0.0f;
  members[1].SetFlat(flat.data(), flat.size());
  const envs::EnvSpec spec = envs::LookupSpec(kLander);
  const std::unique_ptr<actor::Policy> ensemble = EnsemblePolicy(members, spec);
  const EvalScore score = Score(ensemble.get(), kLander, 2, 40);
  const float mean_action[] = {(0.6f + 0.2f) / 2, (-0.4f + 0.0f) / 2};  // in its order
  EXPECT_EQ(score.returns, ConstantActionReturns(mean_action, 2, 40));
  EXPECT_THROW(EnsemblePolicy({}, spec), std::invalid_argument);
  std::vector<nn::Sequential> q = {nn::MakeMlp(4, {4}, 2, &rng)};
  EXPECT_THROW(EnsemblePolicy(q, envs::CartPoleSpec()), std::invalid_argument);
}

TEST(ScorerTest, TheDefaultSeedBaseIsFarFromTrainingSeeds) {
  EXPECT_EQ(kDefaultEvalSeedBase, 1'000'000'000U);
  EXPECT_DOUBLE_EQ(kDefaultEvalEpsilon, 0.05);
}

}  // namespace
}  // namespace rl::evaluator
