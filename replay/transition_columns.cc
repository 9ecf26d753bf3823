#include "replay/transition_columns.h"

#include <algorithm>

#include "common/state_file.h"

namespace rl::replay {

const char* TransitionColumns::Check(const ColumnsView& view, size_t count, int table_width) {
  if (view.action_width < 1 || view.action_width > kMaxActionWidth) {
    return "action_width outside [1, 64]";
  }
  if (table_width > 0 && view.action_width != table_width) {
    return "action_width differs from the table's";
  }
  if (view.action.size() != count * static_cast<size_t>(view.action_width)) {
    return "action size is not count * action_width";
  }
  if (view.reward.size() != count || view.discount.size() != count) {
    return "reward or discount size is not count";
  }
  if (!view.episode_id.empty() && view.episode_id.size() != count) {
    return "episode_id size is neither 0 nor count";
  }
  if (!view.priority.empty() && view.priority.size() != count) {
    return "priority size is neither 0 nor count";
  }
  return nullptr;
}

void TransitionColumns::Allocate(int64_t slots, int action_width) {
  action_width_ = action_width;
  const auto n = static_cast<size_t>(slots);
  action_.assign(n * static_cast<size_t>(action_width), 0.0f);
  reward_.assign(n, 0.0f);
  discount_.assign(n, 0.0f);
  episode_id_.assign(n, -1);
  insert_number_.assign(n, -1);
}

void TransitionColumns::Store(size_t slot, const ColumnsView& view, size_t i, int64_t number) {
  const auto width = static_cast<size_t>(action_width_);
  std::copy_n(view.action.data() + i * width, width, action_.data() + slot * width);
  reward_[slot] = view.reward[i];
  discount_[slot] = view.discount[i];
  episode_id_[slot] = view.episode_id.empty() ? -1 : view.episode_id[i];
  insert_number_[slot] = number;
}

void TransitionColumns::Gather(size_t slot, size_t i, const ColumnSpans& out) const {
  const auto width = static_cast<size_t>(action_width_);
  std::copy_n(action_.data() + slot * width, width, out.action.data() + i * width);
  out.reward[i] = reward_[slot];
  out.discount[i] = discount_[slot];
  out.index[i] = insert_number_[slot];
  if (!out.episode_id.empty()) out.episode_id[i] = episode_id_[slot];
}

bool TransitionColumns::Fits(const ColumnSpans& out, size_t count) const {
  return out.action.size() == count * static_cast<size_t>(action_width_) &&
         out.reward.size() == count && out.discount.size() == count && out.index.size() == count &&
         out.weight.size() == count && (out.episode_id.empty() || out.episode_id.size() == count);
}

int64_t TransitionColumns::memory_bytes() const {
  const size_t bytes =
      (action_.capacity() + reward_.capacity() + discount_.capacity()) * sizeof(float) +
      (episode_id_.capacity() + insert_number_.capacity()) * sizeof(int64_t);
  return static_cast<int64_t>(bytes);
}

void TransitionColumns::Save(const std::string& prefix, StateStream* out) const {
  out->AddFloats(prefix + "action", action_);
  out->AddFloats(prefix + "reward", reward_);
  out->AddFloats(prefix + "discount", discount_);
  out->AddInts(prefix + "episode_id", episode_id_);
  out->AddInts(prefix + "insert_number", insert_number_);
}

void TransitionColumns::Restore(const std::string& prefix, const StateView& in, int64_t slots,
                                int action_width) {
  if (action_width == 0) {
    *this = TransitionColumns();
    slots = 0;
  } else {
    Allocate(slots, action_width);
  }
  in.Copy<float>(prefix + "action", action_);
  in.Copy<float>(prefix + "reward", reward_);
  in.Copy<float>(prefix + "discount", discount_);
  in.Copy<int64_t>(prefix + "episode_id", episode_id_);
  in.Copy<int64_t>(prefix + "insert_number", insert_number_);
}

}  // namespace rl::replay
