#include "replay/rate_limiter.h"

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
  EXPECT_TRUE(limiter.CanSample(1));
  EXPECT_TRUE(limiter.CanSample(5));   // diff 10 - 5 >= min_diff 5
  EXPECT_FALSE(limiter.CanSample(6));  // diff 10 - 6 < 5
}

TEST(RateLimiterTest, AllowsEveryInsertBeforeMinSize) {
  RateLimiter limiter(Options(4.0, 100, 4));
  limiter.Insert(99);
  // Even a large batch: the warm-up is never held back.
  EXPECT_TRUE(limiter.CanInsert(1000));
}

TEST(RateLimiterTest, BlocksInsertsWhenTooFarAheadOfSamples) {
  // max_diff = 2 * 10 + 6 = 26: inserts may go on while diff + 2 <= 26.
  RateLimiter limiter(Options(2.0, 10, 6));
  limiter.Insert(10);                  // diff 20
  EXPECT_TRUE(limiter.CanInsert(3));   // 26
  EXPECT_FALSE(limiter.CanInsert(4));  // 28
  limiter.Insert(3);                   // diff 26
  EXPECT_FALSE(limiter.CanInsert(1));
  EXPECT_DOUBLE_EQ(limiter.diff(), 26.0);
}

TEST(RateLimiterTest, AllowsInsertsAgainAfterSamples) {
  RateLimiter limiter(Options(2.0, 10, 6));
  limiter.Insert(13);  // diff 26 = max_diff
  ASSERT_FALSE(limiter.CanInsert(1));
  ASSERT_TRUE(limiter.CanSample(1));
  limiter.Sample(1);  // diff 25
  EXPECT_FALSE(limiter.CanInsert(1));
  limiter.Sample(1);  // diff 24
  EXPECT_TRUE(limiter.CanInsert(1));
  EXPECT_FALSE(limiter.CanInsert(2));
}

TEST(RateLimiterTest, BlocksSamplesWhenTooFarAheadOfInserts) {
  // min_diff = 2 * 10 - 6 = 14.
  RateLimiter limiter(Options(2.0, 10, 6));
  limiter.Insert(10);  // diff 20
  limiter.Sample(6);   // diff 14
  EXPECT_FALSE(limiter.CanSample(1));
  limiter.Insert(1);  // diff 16
  EXPECT_TRUE(limiter.CanSample(2));
  EXPECT_FALSE(limiter.CanSample(3));
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
