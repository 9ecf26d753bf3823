#include "evaluator/checkpoint_queue.h"

#include <string>

#include <gtest/gtest.h>

namespace rl::evaluator {
namespace {

rlmsg::checkpoint_t Announcement(const std::string& path, int64_t update) {
  rlmsg::checkpoint_t m{};
  m.path = path;
  m.update = update;
  return m;
}

TEST(CheckpointQueueTest, KeepsTheNewestAndCountsSkippedAndDuplicateAnnouncements) {
  EvalHistory history;
  EvalRecord scored;
  scored.checkpoint = "ckpt_10.bin";
  scored.update = 10;
  history.Add(scored);
  CheckpointQueue queue(&history);
  EXPECT_FALSE(queue.has_pending());
  EXPECT_EQ(queue.Offer(Announcement("run/checkpoints/ckpt_10.bin", 10)),
            CheckpointQueue::Outcome::kDuplicate);
  EXPECT_EQ(queue.Offer(Announcement("run/checkpoints/ckpt_20.bin", 20)),
            CheckpointQueue::Outcome::kQueued);
  EXPECT_EQ(queue.Offer(Announcement("run/checkpoints/ckpt_20.bin", 20)),
            CheckpointQueue::Outcome::kDuplicate);
  EXPECT_EQ(queue.Offer(Announcement("run/checkpoints/ckpt_30.bin", 30)),
            CheckpointQueue::Outcome::kQueued);  // ckpt_20 is skipped
  EXPECT_EQ(queue.Offer(Announcement("run/checkpoints/ckpt_25.bin", 25)),
            CheckpointQueue::Outcome::kSkipped);  // older than the pending one
  EXPECT_EQ(queue.skipped(), 2);
  EXPECT_EQ(queue.duplicates(), 2);
  const std::optional<rlmsg::checkpoint_t> next = queue.Take();
  ASSERT_TRUE(next.has_value());
  EXPECT_EQ(next->update, 30);
  EXPECT_FALSE(queue.has_pending());
  EXPECT_FALSE(queue.Take().has_value());
}

}  // namespace
}  // namespace rl::evaluator
