#include "evaluator/checkpoint_queue.h"

#include <filesystem>
#include <utility>

namespace rl::evaluator {

CheckpointQueue::Outcome CheckpointQueue::Offer(const rlmsg::checkpoint_t& announced) {
  // A re-announcement of a scored or pending checkpoint changes nothing.
  const std::string name = std::filesystem::path(announced.path).filename().string();
  if (history_->Contains(name, announced.update) ||
      (pending_ && pending_->path == announced.path && pending_->update == announced.update)) {
    ++duplicates_;
    return Outcome::kDuplicate;
  }
  // Keep the newest; the other one is skipped.
  if (pending_ && announced.update < pending_->update) {
    ++skipped_;
    return Outcome::kSkipped;
  }
  if (pending_) ++skipped_;
  pending_ = announced;
  return Outcome::kQueued;
}

std::optional<rlmsg::checkpoint_t> CheckpointQueue::Take() {
  std::optional<rlmsg::checkpoint_t> taken = std::move(pending_);
  pending_.reset();
  return taken;
}

}  // namespace rl::evaluator
