#include "actor/nstep.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace rl::actor {

template <class T>
BasicNStepAccumulator<T>::BasicNStepAccumulator(int n, double gamma, int obs_size, int action_width)
    : n_(n), gamma_(gamma), obs_size_(obs_size), action_width_(action_width) {
  if (n < 1) throw std::invalid_argument("n-step must be >= 1");
  if (!(gamma >= 0.0 && gamma <= 1.0)) throw std::invalid_argument("gamma must be in [0, 1]");
  if (obs_size < 1) throw std::invalid_argument("observation size must be >= 1");
  if (action_width < 1) throw std::invalid_argument("action width must be >= 1");
  next_obs_.resize(static_cast<size_t>(obs_size));
  steps_.resize(static_cast<size_t>(n));
  for (Pending& p : steps_) {
    p.obs.resize(static_cast<size_t>(obs_size));
    p.action.resize(static_cast<size_t>(action_width));
  }
}

template <class T>
void BasicNStepAccumulator<T>::Add(std::span<const T> obs, std::span<const float> action,
                                   double reward, std::span<const T> next_obs, bool terminated,
                                   bool truncated, const Sink& sink) {
  if (static_cast<int>(obs.size()) != obs_size_ || static_cast<int>(next_obs.size()) != obs_size_) {
    throw std::invalid_argument("observation size differs from the accumulator's");
  }
  if (static_cast<int>(action.size()) != action_width_) {
    throw std::invalid_argument("action width differs from the accumulator's");
  }
  Pending& p = At(count_++);
  std::copy(obs.begin(), obs.end(), p.obs.begin());
  std::copy(action.begin(), action.end(), p.action.begin());
  p.reward = reward;
  std::copy(next_obs.begin(), next_obs.end(), next_obs_.begin());
  if (terminated) {
    while (count_ > 0) EmitOldest(/*bootstrap=*/false, sink);
  } else if (truncated) {
    Flush(sink);
  } else if (count_ == n_) {
    EmitOldest(/*bootstrap=*/true, sink);
  }
}

template <class T>
void BasicNStepAccumulator<T>::Flush(const Sink& sink) {
  while (count_ > 0) EmitOldest(/*bootstrap=*/true, sink);
}

template <class T>
void BasicNStepAccumulator<T>::EmitOldest(bool bootstrap, const Sink& sink) {
  double ret = 0.0;
  double scale = 1.0;
  for (int k = 0; k < count_; ++k) {
    ret += scale * At(k).reward;
    scale *= gamma_;
  }
  // scale is now gamma^k with k the number of pending steps.
  BasicTransition<T> t;
  t.obs = At(0).obs;
  t.action = At(0).action;
  t.reward = static_cast<float>(ret);
  t.discount = bootstrap ? static_cast<float>(scale) : 0.0f;
  t.next_obs = next_obs_;
  sink(t);
  head_ = (head_ + 1) % n_;
  --count_;
}

template class BasicNStepAccumulator<float>;
template class BasicNStepAccumulator<int64_t>;

}  // namespace rl::actor
