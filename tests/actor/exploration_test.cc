#include "actor/exploration.h"

#include <cmath>

#include <gtest/gtest.h>

namespace rl::actor {
namespace {

TEST(ApexEpsilonTest, FollowsTheApeXFormulaForFourActors) {
  EXPECT_DOUBLE_EQ(ApexEpsilon(0, 4), 0.4);
  EXPECT_NEAR(ApexEpsilon(1, 4), std::pow(0.4, 1.0 + 7.0 / 3.0), 1e-12);
  EXPECT_NEAR(ApexEpsilon(2, 4), std::pow(0.4, 1.0 + 14.0 / 3.0), 1e-12);
  EXPECT_NEAR(ApexEpsilon(3, 4), 0.4 * 0.4 * 0.4 * 0.4 * 0.4 * 0.4 * 0.4 * 0.4, 1e-12);
}

TEST(ApexEpsilonTest, ASingleActorUsesTheBase) { EXPECT_DOUBLE_EQ(ApexEpsilon(0, 1), 0.4); }

TEST(LinearEpsilonTest, AnnealsLinearlyThenStays) {
  EXPECT_DOUBLE_EQ(LinearEpsilon(0, 1.0, 0.1, 1000), 1.0);
  EXPECT_NEAR(LinearEpsilon(500, 1.0, 0.1, 1000), 0.55, 1e-12);
  EXPECT_DOUBLE_EQ(LinearEpsilon(1000, 1.0, 0.1, 1000), 0.1);
  EXPECT_DOUBLE_EQ(LinearEpsilon(5000, 1.0, 0.1, 1000), 0.1);
}

TEST(ExplorationConfigTest, RefusesUnknownModesAndBadEpsilons) {
  ExplorationConfig c;
  c.mode = "boltzmann";
  EXPECT_THROW(c.Validate(), std::invalid_argument);
  c.mode = "linear";
  c.end = 1.5;
  EXPECT_THROW(c.Validate(), std::invalid_argument);
  c.end = 0.05;
  EXPECT_NO_THROW(c.Validate());
  EXPECT_DOUBLE_EQ(c.Epsilon(0, 1, 0), 1.0);
}

}  // namespace
}  // namespace rl::actor
