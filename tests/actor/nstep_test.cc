#include "actor/nstep.h"

#include <stdexcept>
#include <vector>

#include <gtest/gtest.h>

namespace rl::actor {
namespace {

struct Out {
  float obs0;
  int action;
  float reward;
  float discount;
  float next0;
};

// Feeds steps with observation [t] -> [t+1] and reward rewards[t]; returns what was emitted.
std::vector<Out> Feed(int n, double gamma, const std::vector<double>& rewards, bool terminate,
                      bool truncate) {
  NStepAccumulator acc(n, gamma, 1);
  std::vector<Out> out;
  auto sink = [&out](const Transition& t) {
    out.push_back({t.obs[0], static_cast<int>(t.action[0]), t.reward, t.discount, t.next_obs[0]});
  };
  for (size_t t = 0; t < rewards.size(); ++t) {
    const float o = static_cast<float>(t);
    const float next = static_cast<float>(t + 1);
    const bool last = t + 1 == rewards.size();
    const float action = static_cast<float>(t);
    acc.Add(std::span<const float>(&o, 1), std::span<const float>(&action, 1), rewards[t],
            std::span<const float>(&next, 1), last && terminate, last && truncate, sink);
  }
  return out;
}

TEST(NStepTest, OneStepIsThePlainTransition) {
  auto out = Feed(1, 0.9, {1.0, 2.0}, false, false);
  ASSERT_EQ(out.size(), 2U);
  EXPECT_FLOAT_EQ(out[0].reward, 1.0f);
  EXPECT_FLOAT_EQ(out[0].discount, 0.9f);
  EXPECT_FLOAT_EQ(out[0].next0, 1.0f);
  EXPECT_EQ(out[1].action, 1);
}

TEST(NStepTest, ThreeStepReturnsAreDiscountedSums) {
  auto out = Feed(3, 0.5, {1.0, 2.0, 3.0, 4.0}, false, false);
  ASSERT_EQ(out.size(), 2U);
  EXPECT_FLOAT_EQ(out[0].obs0, 0.0f);
  EXPECT_FLOAT_EQ(out[0].reward, 1.0f + 0.5f * 2.0f + 0.25f * 3.0f);
  EXPECT_FLOAT_EQ(out[0].discount, 0.125f);
  EXPECT_FLOAT_EQ(out[0].next0, 3.0f);
  EXPECT_FLOAT_EQ(out[1].reward, 2.0f + 0.5f * 3.0f + 0.25f * 4.0f);
  EXPECT_FLOAT_EQ(out[1].next0, 4.0f);
}

TEST(NStepTest, ATerminationFlushesEveryPendingStepWithZeroDiscount) {
  auto out = Feed(3, 0.5, {1.0, 2.0}, true, false);
  ASSERT_EQ(out.size(), 2U);
  EXPECT_FLOAT_EQ(out[0].reward, 1.0f + 0.5f * 2.0f);
  EXPECT_FLOAT_EQ(out[0].discount, 0.0f);
  EXPECT_FLOAT_EQ(out[1].reward, 2.0f);
  EXPECT_FLOAT_EQ(out[1].discount, 0.0f);
}

TEST(NStepTest, ATruncationIsNotATerminalAndBootstrapsFromTheLastObservation) {
  auto out = Feed(3, 0.5, {1.0, 2.0}, false, true);
  ASSERT_EQ(out.size(), 2U);
  EXPECT_FLOAT_EQ(out[0].reward, 2.0f);
  EXPECT_FLOAT_EQ(out[0].discount, 0.25f);  // two steps left before the cut
  EXPECT_FLOAT_EQ(out[0].next0, 2.0f);
  EXPECT_FLOAT_EQ(out[1].discount, 0.5f);
  EXPECT_FLOAT_EQ(out[1].next0, 2.0f);
}

TEST(NStepTest, RefusesBadParameters) {
  EXPECT_THROW(NStepAccumulator(0, 0.9, 1), std::invalid_argument);
  EXPECT_THROW(NStepAccumulator(1, 1.5, 1), std::invalid_argument);
}

// Continuous actions travel as vectors: each transition keeps the action of its first step.
TEST(NStepTest, ActionVectorsStayWithTheirStep) {
  NStepAccumulator acc(2, 0.5, 1, 3);
  std::vector<std::vector<float>> actions;
  auto sink = [&actions](const Transition& t) {
    actions.emplace_back(t.action.begin(), t.action.end());
  };
  for (int t = 0; t < 4; ++t) {
    const float o = static_cast<float>(t), next = o + 1;
    const float a[] = {o, -o, 0.5f * o};
    acc.Add(std::span<const float>(&o, 1), a, 1.0, std::span<const float>(&next, 1), false, t == 3,
            sink);
  }
  ASSERT_EQ(actions.size(), 4U);
  EXPECT_EQ(actions[1], (std::vector<float>{1, -1, 0.5f}));
  EXPECT_EQ(actions[3], (std::vector<float>{3, -3, 1.5f}));
  const float wrong[] = {0, 0};
  const float o = 0;
  EXPECT_THROW(acc.Add(std::span<const float>(&o, 1), wrong, 1.0, std::span<const float>(&o, 1),
                       false, false, sink),
               std::invalid_argument);
}

}  // namespace
}  // namespace rl::actor
