// BatchDecoder: turns a sample reply (flat floats or pixel stacks) into the network inputs of an
// Algorithm, once for both algorithm families: flat observations are copied, pixels divided by 255,
// and with augment_shift > 0 every pixel observation and next observation is shifted by its own
// random offset of up to augment_shift pixels in y and x, edges repeated (DrQ, Kostrikov et al.
// 2020). Buffers are reused: no allocation once the batch size is stable.
#pragma once

#include <cstdint>
#include <random>
#include <vector>

#include "envs/env.h"
#include "learner/algorithm.h"
#include "rlmsg/sample_batch_t.hpp"

namespace rl::learner {

class BatchDecoder {
 public:
  /// Decodes batches of `spec`'s observations and actions. Throws std::invalid_argument for
  /// augment_shift < 0, or > 0 for an env without frames.
  BatchDecoder(const envs::EnvSpec& spec, int augment_shift, uint64_t seed);

  /// Decodes `m`. Returns nullptr, or why the reply does not fit the env (observation size or
  /// kind, action width), in which case `out` is unusable. The Batch points into this decoder and
  /// into `m`, both of which must outlive its use.
  const char* Decode(const rlmsg::sample_batch_t& m, Batch* out);

  /// The generator of the random shifts (a restarted learner restores it).
  std::mt19937_64& shift_rng() { return rng_; }
  const std::mt19937_64& shift_rng() const { return rng_; }

 private:
  void Shifted(const std::vector<uint8_t>& pixels, int n, nn::Matrix* out);

  envs::EnvSpec spec_;
  int augment_shift_;
  std::mt19937_64 rng_;
  nn::Matrix obs_, next_obs_;
  std::vector<int> shift_y_, shift_x_;
};

}  // namespace rl::learner
