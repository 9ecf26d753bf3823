#include "evaluator/checkpoint_queue.h"

#include <filesystem>
#include <fstream>
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
            CheckpointQueue::Outcome::kQueued);  // ckpt_20 is superseded (no backlog: skipped)
  EXPECT_EQ(queue.Offer(Announcement("run/checkpoints/ckpt_25.bin", 25)),
            CheckpointQueue::Outcome::kSuperseded);  // older than the pending one
  EXPECT_EQ(queue.skipped(), 2);
  EXPECT_EQ(queue.duplicates(), 2);
  const std::optional<rlmsg::checkpoint_t> next = queue.Take();
  ASSERT_TRUE(next.has_value());
  EXPECT_EQ(next->update, 30);
  EXPECT_FALSE(queue.has_pending());
  EXPECT_FALSE(queue.Take().has_value());
}

TEST(CheckpointQueueTest, SupersededCheckpointsWaitInTheBacklogNewestFirstUpToItsLimit) {
  const std::filesystem::path dir =
      std::filesystem::path(::testing::TempDir()) / "checkpoint_queue_backlog";
  std::filesystem::create_directories(dir);
  const auto file = [&](int64_t update) {
    std::string path = (dir / ("ckpt_" + std::to_string(update) + ".bin")).string();
    std::ofstream(path) << "x";
    return path;
  };
  EvalHistory history;
  CheckpointQueue queue(&history, 2);
  for (const int64_t update : {10, 20, 30, 40}) {
    EXPECT_EQ(queue.Offer(Announcement(file(update), update)), CheckpointQueue::Outcome::kQueued);
  }
  EXPECT_EQ(queue.Offer(Announcement(file(35), 35)), CheckpointQueue::Outcome::kSuperseded);
  // 10, 20, 30 and 35 superseded; the two newest wait, 10 and 20 are skipped.
  EXPECT_EQ(queue.backlog(), 2);
  EXPECT_EQ(queue.skipped(), 2);
  EXPECT_EQ(queue.Offer(Announcement(file(30), 30)), CheckpointQueue::Outcome::kDuplicate);
  ASSERT_TRUE(queue.has_pending());
  EXPECT_EQ(queue.Take()->update, 40);
  // The newest waiting one first; a file deleted meanwhile is skipped.
  std::filesystem::remove(dir / "ckpt_35.bin");
  const std::optional<rlmsg::checkpoint_t> late = queue.TakeFromBacklog();
  ASSERT_TRUE(late.has_value());
  EXPECT_EQ(late->update, 30);
  EXPECT_EQ(queue.skipped(), 3);
  EXPECT_FALSE(queue.TakeFromBacklog().has_value());
  EXPECT_EQ(queue.backlog(), 0);
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace rl::evaluator
