// NStepAccumulator turns one environment's steps into n-step transitions.
//
// For each step t it emits (o_t, a_t, R_t, d_t, o_{t+k}) with R_t = sum_{j<k} gamma^j r_{t+j}:
// k = n while the episode goes on (d_t = gamma^n); at a termination every pending step is
// emitted with d_t = 0; at a time-limit truncation (not a terminal) every pending step is emitted
// with k the steps left before the cut and d_t = gamma^k, bootstrapping from the last
// observation. With n = 1 this is the one-step transition of DQN. Every step becomes exactly one
// transition (Flush() emits the pending ones of an episode cut short).
//
// Observations are float vectors (BasicNStepAccumulator<float>, flat envs) or, for pixel envs,
// the frame ids of a stack (BasicNStepAccumulator<int64_t>): the frames themselves travel once.
#pragma once

#include <cstdint>
#include <functional>
#include <span>
#include <vector>

namespace rl::actor {

template <class T>
struct BasicTransition {
  std::span<const T> obs;
  std::span<const float> action;  // action_width floats (a discrete action: its index)
  float reward = 0;               // n-step discounted return
  float discount = 0;             // gamma^k, or 0 after a termination
  std::span<const T> next_obs;
};

template <class T>
class BasicNStepAccumulator {
 public:
  using Sink = std::function<void(const BasicTransition<T>&)>;

  BasicNStepAccumulator(int n, double gamma, int obs_size, int action_width = 1);

  // Records the step taken from `obs` with `action`, which gave `reward` and `next_obs`, and
  // emits every transition that is now complete.
  void Add(std::span<const T> obs, std::span<const float> action, double reward,
           std::span<const T> next_obs, bool terminated, bool truncated, const Sink& sink);

  // Emits every pending step as a time-limit truncation would (discount gamma^k, bootstrapping
  // from the last observation): the episode is cut here, e.g. because the actor stops.
  void Flush(const Sink& sink);

  // Steps waiting for their n-step return.
  int pending() const { return count_; }

 private:
  // A ring of n preallocated steps, so that stepping allocates nothing.
  struct Pending {
    std::vector<T> obs;
    std::vector<float> action;
    double reward = 0;
  };
  Pending& At(int k) { return steps_[static_cast<size_t>((head_ + k) % n_)]; }
  // Emits the oldest pending step with the return of all pending steps; `bootstrap` says
  // whether the last observation is bootstrapped from (discount gamma^k) or not (0).
  void EmitOldest(bool bootstrap, const Sink& sink);

  int n_;
  double gamma_;
  int obs_size_;
  int action_width_;
  std::vector<Pending> steps_;
  int head_ = 0;   // oldest pending step
  int count_ = 0;  // pending steps
  std::vector<T> next_obs_;
};

extern template class BasicNStepAccumulator<float>;
extern template class BasicNStepAccumulator<int64_t>;

using Transition = BasicTransition<float>;
using NStepAccumulator = BasicNStepAccumulator<float>;
using FrameTransition = BasicTransition<int64_t>;
using FrameNStepAccumulator = BasicNStepAccumulator<int64_t>;

}  // namespace rl::actor
