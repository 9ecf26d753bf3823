#include "common/text_format.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <utility>

namespace rl {
namespace {

TEST(TextFormatTest, ScoresKeepTwoDecimalsBelowTenRoundedDown) {
  EXPECT_EQ(Score(0.356), "0.35");
  EXPECT_EQ(Score(-9.984), "-9.99");
  EXPECT_EQ(Score(475.04), "475.0");
  EXPECT_EQ(Score(475.0), "475.0");
  EXPECT_EQ(Score(474.99999999999994), "475.0");
  EXPECT_EQ(Score(-12.25), "-12.3");
  // Below a goal never reads as the goal.
  EXPECT_EQ(Score(899.96), "899.9");
  EXPECT_EQ(Score(-200.04), "-200.1");
}

TEST(TextFormatTest, ThousandsAreSeparated) {
  const std::pair<int64_t, const char*> cases[] = {
      {0, "0"}, {999, "999"}, {1000, "1,000"}, {1234567, "1,234,567"}, {-45678, "-45,678"}};
  for (const auto& [n, text] : cases) EXPECT_EQ(Thousands(n), text) << n;
}

TEST(TextFormatTest, DurationsReadAsSecondsMinutesOrHours) {
  EXPECT_EQ(Duration(4.25), "4.2 s");
  EXPECT_EQ(Duration(42), "42 s");
  EXPECT_EQ(Duration(725), "12 min 05 s");
  EXPECT_EQ(Duration(7300), "2 h 01 min");
  EXPECT_EQ(Duration(-1), "-");
  EXPECT_EQ(Duration(std::nan(""), "n/a"), "n/a");
}

}  // namespace
}  // namespace rl
