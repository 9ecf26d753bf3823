#include "envs/registry.h"

#include <algorithm>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "envs/box2d/lunar_lander.h"
#include "envs/cartpole.h"
#include "envs/time_limit.h"

namespace rl::envs {
namespace {

TEST(RegistryTest, CartPoleV1IsACartPoleWithA500StepLimit) {
  auto env = MakeEnv("CartPole-v1");
  ASSERT_NE(env, nullptr);
  EXPECT_EQ(env->spec().id, "CartPole-v1");
  EXPECT_EQ(env->spec().observation_size, 4);
  EXPECT_EQ(env->spec().num_actions, 2);
  EXPECT_EQ(env->spec().max_episode_steps, 500);
  EXPECT_EQ(env->spec().reward_threshold, 475.0);
  auto* limit = dynamic_cast<TimeLimit*>(env.get());
  ASSERT_NE(limit, nullptr);
  EXPECT_EQ(limit->max_episode_steps(), 500);
  EXPECT_NE(dynamic_cast<CartPole*>(&limit->wrapped_env()), nullptr);
}

TEST(RegistryTest, LunarLanderV3VariantsAreLunarLandersWithA1000StepLimit) {
  for (const std::string id : {"LunarLander-v3", "LunarLanderContinuous-v3"}) {
    auto env = MakeEnv(id);
    ASSERT_NE(env, nullptr);
    EXPECT_EQ(env->spec().id, id);
    EXPECT_EQ(env->spec().observation_size, 8);
    EXPECT_EQ(env->spec().max_episode_steps, 1000);
    EXPECT_EQ(env->spec().reward_threshold, 200.0);
    auto* limit = dynamic_cast<TimeLimit*>(env.get());
    ASSERT_NE(limit, nullptr) << id;
    EXPECT_EQ(limit->max_episode_steps(), 1000);
    auto* lander = dynamic_cast<LunarLander*>(&limit->wrapped_env());
    ASSERT_NE(lander, nullptr) << id;
    EXPECT_EQ(lander->config().continuous, id == "LunarLanderContinuous-v3");
  }
  EXPECT_EQ(MakeEnv("LunarLander-v3")->spec().num_actions, 4);
  EXPECT_EQ(MakeEnv("LunarLander-v3")->spec().action_dim, 0);
  EXPECT_EQ(MakeEnv("LunarLanderContinuous-v3")->spec().num_actions, 0);
  EXPECT_EQ(MakeEnv("LunarLanderContinuous-v3")->spec().action_dim, 2);
}

TEST(RegistryTest, EachCallBuildsAnIndependentEnv) {
  auto a = MakeEnv("CartPole-v1");
  auto b = MakeEnv("CartPole-v1");
  EXPECT_NE(a.get(), b.get());
  a->Reset(1);
  b->Reset(1);
  a->Step(DiscreteAction(1));
  EXPECT_NE(a->observation()[1], b->observation()[1]);
}

TEST(RegistryTest, ListsTheRegisteredIds) {
  const std::vector<std::string> ids = RegisteredEnvs();
  EXPECT_NE(std::find(ids.begin(), ids.end(), "CartPole-v1"), ids.end());
  EXPECT_NE(std::find(ids.begin(), ids.end(), "LunarLander-v3"), ids.end());
  EXPECT_NE(std::find(ids.begin(), ids.end(), "LunarLanderContinuous-v3"), ids.end());
  EXPECT_TRUE(std::is_sorted(ids.begin(), ids.end()));
  for (const std::string& id : ids) EXPECT_NE(MakeEnv(id), nullptr) << id;
}

TEST(RegistryTest, UnknownIdThrowsNamingTheIdAndTheKnownIds) {
  try {
    MakeEnv("CartPole-v9");
    FAIL() << "expected std::invalid_argument";
  } catch (const std::invalid_argument& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("CartPole-v9"), std::string::npos) << message;
    EXPECT_NE(message.find("CartPole-v1"), std::string::npos) << message;
    EXPECT_NE(message.find("LunarLander-v3"), std::string::npos) << message;
  }
  EXPECT_THROW(MakeEnv(""), std::invalid_argument);
}

}  // namespace
}  // namespace rl::envs
