// WeightsAssembler puts the chunks of a weights version back together.
//
// A version becomes available only when all its chunks arrived and the CRC-32 of the whole
// buffer matches; a lost chunk costs that version, never a corrupted policy. Chunks of versions
// older than the newest complete one are ignored. At most two versions are assembled at once.
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "rlmsg/weights_chunk_t.hpp"

namespace rl::actor {

struct Weights {
  int64_t version = -1;
  std::string architecture;
  std::vector<float> params;
};

class WeightsAssembler {
 public:
  // Adds a chunk (already validated by the bus: offsets inside the buffer). Returns true when
  // this chunk completed a version that is newer than the last one; Take() then hands it out.
  bool Add(const rlmsg::weights_chunk_t& chunk);

  // The newest complete version, once; empty if none completed since the last call.
  std::optional<Weights> Take();

  int64_t complete_version() const { return complete_version_; }
  // Versions dropped because their checksum did not match or their chunks disagreed.
  int64_t rejected() const { return rejected_; }

 private:
  struct Partial {
    std::string architecture;
    std::vector<float> params;
    std::vector<bool> have;
    int received = 0;
    int64_t crc32 = 0;
  };

  std::map<int64_t, Partial> partial_;  // by version
  std::optional<Weights> ready_;
  int64_t complete_version_ = -1;
  int64_t rejected_ = 0;
};

}  // namespace rl::actor
