// WeightsPublisher sends versions of the network's parameters as paced chunks on RL_WEIGHTS.
//
// Start() takes a snapshot; Tick() publishes at most chunks_per_tick chunks of it, so a large
// network goes out over several loop iterations instead of in one burst that overflows the
// receivers' socket buffers. A new Start() replaces an unfinished version.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "common/lcm_bus.h"
#include "rlmsg/weights_chunk_t.hpp"

namespace rl::learner {

// Largest chunk: 12,000 floats (48 KB), small enough to stay visible in lcm-spy.
inline constexpr int kMaxChunkFloats = 12000;

// Splits a parameter buffer into the chunks of one version (headers left for the bus to fill).
std::vector<rlmsg::weights_chunk_t> MakeWeightChunks(int64_t version,
                                                     const std::string& architecture,
                                                     const std::vector<float>& params,
                                                     int max_chunk_floats = kMaxChunkFloats);

class WeightsPublisher {
 public:
  explicit WeightsPublisher(Bus* bus, int chunks_per_tick = 16)
      : bus_(bus), chunks_per_tick_(chunks_per_tick) {}

  void Start(int64_t version, const std::string& architecture, const std::vector<float>& params);
  void Tick();
  bool busy() const { return next_ < chunks_.size(); }
  // Newest version whose chunks have all been published (-1: none yet).
  int64_t published_version() const { return published_version_; }

 private:
  Bus* bus_;
  int chunks_per_tick_;
  std::vector<rlmsg::weights_chunk_t> chunks_;
  size_t next_ = 0;
  int64_t published_version_ = -1;
};

}  // namespace rl::learner
