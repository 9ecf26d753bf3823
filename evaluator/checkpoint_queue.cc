#include "evaluator/checkpoint_queue.h"

#include <algorithm>
#include <filesystem>
#include <utility>

namespace rl::evaluator {
namespace {

bool Same(const rlmsg::checkpoint_t& a, const rlmsg::checkpoint_t& b) {
  return a.path == b.path && a.update == b.update;
}

}  // namespace

CheckpointQueue::Outcome CheckpointQueue::Offer(const rlmsg::checkpoint_t& announced) {
  // A re-announcement of a scored, pending or waiting checkpoint changes nothing.
  const std::string name = std::filesystem::path(announced.path).filename().string();
  const auto waiting = backlog_.equal_range(announced.update);
  if (history_->Contains(name, announced.update) || (pending_ && Same(*pending_, announced)) ||
      std::any_of(waiting.first, waiting.second,
                  [&](const auto& entry) { return Same(entry.second, announced); })) {
    ++duplicates_;
    return Outcome::kDuplicate;
  }
  // The newest goes first; the other one waits.
  if (pending_ && announced.update < pending_->update) {
    Defer(announced);
    return Outcome::kSuperseded;
  }
  if (pending_) Defer(*pending_);
  pending_ = announced;
  return Outcome::kQueued;
}

void CheckpointQueue::Defer(const rlmsg::checkpoint_t& superseded) {
  backlog_.emplace(superseded.update, superseded);
  while (static_cast<int>(backlog_.size()) > backlog_limit_) {
    backlog_.erase(backlog_.begin());
    ++skipped_;
  }
}

std::optional<rlmsg::checkpoint_t> CheckpointQueue::Take() {
  std::optional<rlmsg::checkpoint_t> taken = std::move(pending_);
  pending_.reset();
  return taken;
}

std::optional<rlmsg::checkpoint_t> CheckpointQueue::TakeFromBacklog() {
  while (!backlog_.empty()) {
    auto newest = std::prev(backlog_.end());
    rlmsg::checkpoint_t taken = std::move(newest->second);
    backlog_.erase(newest);
    std::error_code ec;
    if (std::filesystem::is_regular_file(taken.path, ec)) return taken;
    ++skipped_;
  }
  return std::nullopt;
}

}  // namespace rl::evaluator
