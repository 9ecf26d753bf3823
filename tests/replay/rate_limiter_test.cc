#include "replay/rate_limiter.h"

#include <cstdint>
#include <stdexcept>

#include <gtest/gtest.h>

namespace rl::replay {
namespace {

RateLimiterOptions Options(double spi, int64_t min_size, double error_buffer) {
  RateLimiterOptions o;
  o.samples_per_insert = spi;
  o.min_size_to_sample = min_size;
  o.error_buffer = error_buffer;
  return o;
}

// The largest batch up to 100 that the limiter admits now: CanInsert(n) (CanSample(n)) holds for
// n = 1 .. the result and not for the next n; 0 when it holds for none.
int64_t LargestInsert(const RateLimiter& limiter) {
  int64_t n = 0;
  while (n < 100 && limiter.CanInsert(n + 1)) ++n;
  return n;
}
int64_t LargestSample(const RateLimiter& limiter) {
  int64_t n = 0;
  while (n < 100 && limiter.CanSample(n + 1)) ++n;
  return n;
}

TEST(RateLimiterTest, DefaultOptionsAreValid) { EXPECT_NO_THROW(RateLimiterOptions{}.Validate()); }

TEST(RateLimiterTest, RefusesBadOptions) {
  EXPECT_THROW(RateLimiter(Options(8, 0, 100)), std::invalid_argument);     // min size
  EXPECT_THROW(RateLimiter(Options(8, 10, -1)), std::invalid_argument);     // negative buffer
  EXPECT_THROW(RateLimiter(Options(8, 10, 7)), std::invalid_argument);      // buffer < SPI
  EXPECT_THROW(RateLimiter(Options(0.5, 10, 0.5)), std::invalid_argument);  // buffer < 1
  EXPECT_NO_THROW(RateLimiter(Options(8, 10, 8)));
  EXPECT_NO_THROW(RateLimiter(Options(0, 10, 0)));  // disabled: any buffer
}

TEST(RateLimiterTest, BlocksSamplesUntilMinInsertsReached) {
  RateLimiter limiter(Options(1.0, 10, 5));
  limiter.Insert(9);
  EXPECT_FALSE(limiter.CanSample(1));
  EXPECT_TRUE(limiter.CanInsert(1));
  limiter.Insert(1);
  EXPECT_EQ(LargestSample(limiter), 5);  // diff 10 - 5 >= min_diff 5, 10 - 6 < 5
}

TEST(RateLimiterTest, AllowsEveryInsertBeforeMinSize) {
  RateLimiter limiter(Options(4.0, 100, 4));
  limiter.Insert(99);
  // Even a large batch: the warm-up is never held back.
  EXPECT_TRUE(limiter.CanInsert(1000));
}

// Two samples per insert, a min size of 10 and an error buffer of 6: an insert of n is allowed
// while diff + 2 n <= max_diff = 2 * 10 + 6 = 26, a sample of n while diff - n >= min_diff =
// 2 * 10 - 6 = 14.
class RateLimiterBandTest : public ::testing::Test {
 protected:
  RateLimiter limiter_{Options(2.0, 10, 6)};
};

TEST_F(RateLimiterBandTest, BlocksInsertsWhenTooFarAheadOfSamples) {
  limiter_.Insert(10);                    // diff 20
  EXPECT_EQ(LargestInsert(limiter_), 3);  // 26, not 28
  limiter_.Insert(3);                     // diff 26
  EXPECT_EQ(LargestInsert(limiter_), 0);
  EXPECT_DOUBLE_EQ(limiter_.diff(), 26.0);
}

TEST_F(RateLimiterBandTest, AllowsInsertsAgainAfterSamples) {
  limiter_.Insert(13);  // diff 26 = max_diff
  ASSERT_EQ(LargestInsert(limiter_), 0);
  ASSERT_TRUE(limiter_.CanSample(1));
  limiter_.Sample(1);  // diff 25
  EXPECT_EQ(LargestInsert(limiter_), 0);
  limiter_.Sample(1);  // diff 24
  EXPECT_EQ(LargestInsert(limiter_), 1);
}

TEST_F(RateLimiterBandTest, BlocksSamplesWhenTooFarAheadOfInserts) {
  limiter_.Insert(10);  // diff 20
  limiter_.Sample(6);   // diff 14
  EXPECT_EQ(LargestSample(limiter_), 0);
  limiter_.Insert(1);  // diff 16
  EXPECT_EQ(LargestSample(limiter_), 2);
}

TEST(RateLimiterTest, NeverBlocksBothSidesForBatchesUpToTheLimit) {
  // Whatever the state, an insert of one or a sample of max_sample_batch() is possible.
  RateLimiter limiter(Options(8.0, 100, 200));
  const int64_t batch = limiter.max_sample_batch();
  ASSERT_EQ(batch, 392);
  limiter.Insert(100);
  for (int step = 0; step < 2000; ++step) {
    const bool can_insert = limiter.CanInsert(1);
    const bool can_sample = limiter.CanSample(batch);
    ASSERT_TRUE(can_insert || can_sample) << "deadlock at step " << step;
    // Alternate preferences so that both extremes are visited.
    if (can_sample && (step % 50 < 25 || !can_insert)) {
      limiter.Sample(batch);
    } else {
      limiter.Insert(1);
    }
  }
  EXPECT_GT(limiter.samples(), 0);
}

// The credit is exactly the number of single inserts CanInsert admits, before and after min_size,
// and never negative; -1 without a ratio.
TEST(RateLimiterTest, InsertCreditCountsTheInsertsCanInsertAdmits) {
  RateLimiter limiter(Options(4.0, 10, 8.0));  // max_diff = 48
  const auto admitted = [](RateLimiter copy) {
    int64_t n = 0;
    while (copy.CanInsert(1) && n < 1000) {
      copy.Insert(1);
      ++n;
    }
    return n;
  };
  EXPECT_EQ(limiter.InsertCredit(), 12);  // (48 - 0) / 4
  EXPECT_EQ(limiter.InsertCredit(), admitted(limiter));
  limiter.Insert(7);
  EXPECT_EQ(limiter.InsertCredit(), admitted(limiter));
  limiter.Insert(5);  // 12 in: diff 48, at the limit
  EXPECT_EQ(limiter.InsertCredit(), 0);
  EXPECT_FALSE(limiter.CanInsert(1));
  limiter.Insert(3);  // stored anyway: diff 60, past the limit
  EXPECT_EQ(limiter.InsertCredit(), 0);
  limiter.Sample(22);  // diff 38
  EXPECT_EQ(limiter.InsertCredit(), 2);
  EXPECT_EQ(limiter.InsertCredit(), admitted(limiter));
  EXPECT_EQ(RateLimiter(Options(0.0, 10, 8.0)).InsertCredit(), -1);
}

TEST(RateLimiterTest, ZeroSamplesPerInsertDisablesTheRatio) {
  RateLimiter limiter(Options(0.0, 10, 0));
  EXPECT_EQ(limiter.max_sample_batch(), 0);
  limiter.Insert(5);
  EXPECT_FALSE(limiter.CanSample(1));  // min size still applies
  limiter.Insert(5);
  EXPECT_TRUE(limiter.CanSample(1000000));
  limiter.Sample(1000000);
  EXPECT_TRUE(limiter.CanSample(1000000));
  limiter.Insert(1000000);
  EXPECT_TRUE(limiter.CanInsert(1000000));
}

TEST(RateLimiterTest, NegativeSamplesPerInsertDisablesTheRatio) {
  RateLimiter limiter(Options(-1.0, 1, 0));
  limiter.Insert(1);
  limiter.Sample(100000);
  EXPECT_TRUE(limiter.CanSample(100000));
  EXPECT_TRUE(limiter.CanInsert(100000));
}

TEST(RateLimiterTest, ReportsSamplesPerInsertSinceMinSize) {
  RateLimiter limiter(Options(4.0, 10, 100));
  limiter.Insert(10);
  EXPECT_EQ(limiter.samples_per_insert(), 0.0);
  limiter.Insert(5);
  limiter.Sample(20);
  EXPECT_DOUBLE_EQ(limiter.samples_per_insert(), 4.0);
}

}  // namespace
}  // namespace rl::replay
