// Helpers for tests of the learning algorithms: a batch that owns its arrays, and a network's
// parameters as one vector.
#pragma once

#include <vector>

#include "learner/algorithm.h"

namespace rl::learner {

/// Transitions with their observations as columns; view() lends them to Algorithm::Update.
struct OwnedBatch {
  nn::Matrix obs, next_obs;
  std::vector<float> action, reward, discount, weight;

  /// The reward.size() transitions, with actions `action_width` floats wide. Valid while *this
  /// lives and its vectors keep their sizes.
  Batch view(int action_width) const {
    return {static_cast<int>(reward.size()),
            action_width,
            &obs,
            &next_obs,
            action,
            reward,
            discount,
            weight};
  }
};

/// The parameters of a network (nn::Sequential, nn::ActionValueNet) as one vector.
template <typename Net>
std::vector<float> Flat(const Net& net) {
  std::vector<float> flat;
  net.GetFlat(&flat);
  return flat;
}

}  // namespace rl::learner
