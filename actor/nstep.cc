#include "actor/nstep.h"

#include <cmath>
#include <stdexcept>

namespace rl::actor {

NStepAccumulator::NStepAccumulator(int n, double gamma, int obs_size)
    : n_(n), gamma_(gamma), obs_size_(obs_size) {
  if (n < 1) throw std::invalid_argument("n-step must be >= 1");
  if (!(gamma >= 0.0 && gamma <= 1.0)) throw std::invalid_argument("gamma must be in [0, 1]");
  if (obs_size < 1) throw std::invalid_argument("observation size must be >= 1");
  next_obs_.resize(static_cast<size_t>(obs_size));
}

void NStepAccumulator::Add(std::span<const float> obs, int action, double reward,
                           std::span<const float> next_obs, bool terminated, bool truncated,
                           const Sink& sink) {
  if (static_cast<int>(obs.size()) != obs_size_ || static_cast<int>(next_obs.size()) != obs_size_) {
    throw std::invalid_argument("observation size differs from the accumulator's");
  }
  steps_.push_back(Pending{std::vector<float>(obs.begin(), obs.end()), action, reward});
  next_obs_.assign(next_obs.begin(), next_obs.end());
  if (terminated) {
    while (!steps_.empty()) EmitOldest(/*bootstrap=*/false, sink);
  } else if (truncated) {
    while (!steps_.empty()) EmitOldest(/*bootstrap=*/true, sink);
  } else if (static_cast<int>(steps_.size()) == n_) {
    EmitOldest(/*bootstrap=*/true, sink);
  }
}

void NStepAccumulator::EmitOldest(bool bootstrap, const Sink& sink) {
  double ret = 0.0;
  double scale = 1.0;
  for (const Pending& p : steps_) {
    ret += scale * p.reward;
    scale *= gamma_;
  }
  // scale is now gamma^k with k the number of pending steps.
  Transition t;
  t.obs = steps_.front().obs;
  t.action = steps_.front().action;
  t.reward = static_cast<float>(ret);
  t.discount = bootstrap ? static_cast<float>(scale) : 0.0f;
  t.next_obs = next_obs_;
  sink(t);
  steps_.pop_front();
}

}  // namespace rl::actor
