// The algorithm seam of the learner: DQN (discrete actions) and TD3 (continuous actions) share
// everything but the update. The learner decodes each sampled batch once (batch_decoder.h:
// observations as network inputs, pixels divided by 255 and randomly shifted when asked) and hands
// it to the Algorithm; what it broadcasts to actors and checkpoints is the algorithm's policy
// network (the Q-network for DQN, the actor for TD3).
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "common/state_file.h"
#include "nn/sequential.h"
#include "nn/tensor.h"

namespace rl::learner {

/// A decoded batch of `count` transitions: obs and next_obs are network inputs (observation size
/// x count, one transition per column); action holds count * action_width floats (transition i
/// at [i * action_width, (i + 1) * action_width); a discrete action is its index); reward,
/// discount (gamma^k, or 0 after a termination) and weight (importance weights) count values each.
struct Batch {
  int count = 0;
  int action_width = 0;
  const nn::Matrix* obs = nullptr;
  const nn::Matrix* next_obs = nullptr;
  std::span<const float> action;
  std::span<const float> reward;
  std::span<const float> discount;
  std::span<const float> weight;  // empty: all ones
};

struct UpdateResult {
  float loss = 0;    // mean (weighted) loss of the batch (TD3: the critics')
  float mean_q = 0;  // mean Q of the batch's actions
  float grad_norm = 0;
};

class Algorithm {
 public:
  virtual ~Algorithm() = default;

  /// One update on the batch. Throws std::invalid_argument on a batch that does not fit the
  /// networks (observation size, action width, a discrete action that is not an index in range);
  /// the networks are unchanged then.
  virtual UpdateResult Update(const Batch& batch) = 0;
  /// |TD error| of each transition of the last Update (the replay's new priorities).
  virtual const std::vector<float>& last_td_errors() const = 0;
  /// The network actors act with and the evaluator scores.
  virtual nn::Sequential& policy() = 0;
  /// Updates so far.
  virtual int64_t updates() const = 0;
  /// A short description for the learner's ready line.
  virtual std::string Describe() const = 0;
  /// Sets every optimizer's step size to `scale` (>= 0) times its configured one, from the next
  /// Update on (the learner's learning-rate decay). Not part of the state: the learner sets it
  /// again before each update.
  virtual void SetLearningRateScale(float scale) = 0;

  /// Adds to `state` everything needed to continue exactly where this algorithm is: networks and
  /// their targets (with their architecture strings), optimizer states, counters and random
  /// generators. O(parameters); allocates the copies.
  virtual void SaveState(StateFile* state) const = 0;
  /// Restores what SaveState() wrote. Throws std::runtime_error naming the first section that
  /// does not fit (missing, another architecture, another size); the algorithm is then partly
  /// restored and must not be used.
  virtual void LoadState(const StateFile& state) = 0;
};

}  // namespace rl::learner
