#include "learner/parameter_average.h"

#include <algorithm>
#include <stdexcept>

namespace rl::learner {

ParameterAverage::ParameterAverage(int horizon) : horizon_(horizon) {
  if (horizon < 1) throw std::invalid_argument("the average's horizon must be >= 1");
}

void ParameterAverage::Add(std::span<const float> params) {
  if (values_.size() != params.size()) {
    values_.assign(params.begin(), params.end());
    count_ = 1;
    return;
  }
  count_ = std::min<int64_t>(count_ + 1, horizon_);
  const float w = 1.0f / static_cast<float>(count_);
  for (size_t i = 0; i < values_.size(); ++i) values_[i] += w * (params[i] - values_[i]);
}

void ParameterAverage::Save(StateFile* state, const std::string& name) const {
  if (values_.empty()) return;
  state->PutFloats(name, values_);
  state->PutInt(name + "_count", count_);
}

void ParameterAverage::Load(const StateFile& state, const std::string& name, int64_t size) {
  if (!state.Has(name)) return;
  const std::span<const float> saved = state.Floats(name, size);
  values_.assign(saved.begin(), saved.end());
  count_ = std::clamp<int64_t>(state.Int(name + "_count"), 1, horizon_);
}

}  // namespace rl::learner
