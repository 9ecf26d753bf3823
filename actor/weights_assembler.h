// WeightsAssembler puts the chunks of a weights version back together.
//
// A version becomes available only when all its chunks arrived and the CRC-32 of the whole
// buffer matches; a lost chunk costs that version, never a corrupted policy. Chunks of versions
// older than the newest complete one are ignored. At most two versions are assembled at once.
//
// What a version may cost is bounded by the network the receiver expects, not by the message:
// before it allocates anything for a version, the assembler asks its `size_of` function how many
// floats the version's architecture holds for this receiver (the actor builds that network and
// checks that it fits its env), and refuses the version when the architecture is refused, when
// its total_size is another, or when it claims more chunks than floats. So a forged chunk can make
// a receiver hold at most two buffers of the size of a network it would accept.
#pragma once

#include <cstdint>
#include <functional>
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
  // The floats of the parameter buffer (nn::Sequential::FlatSize()) of a network of
  // `architecture` that the receiver accepts, or a negative number when it refuses the
  // architecture. Called once per architecture in a row (the last answer is kept), on the first
  // chunk of a version.
  using SizeOf = std::function<int64_t(const std::string& architecture)>;

  explicit WeightsAssembler(SizeOf size_of);

  // Adds a chunk (already validated by the bus: offsets inside the buffer). Returns true when
  // this chunk completed a version that is newer than the last one; Take() then hands it out.
  bool Add(const rlmsg::weights_chunk_t& chunk);

  // The newest complete version, once; empty if none completed since the last call.
  std::optional<Weights> Take();

  int64_t complete_version() const { return complete_version_; }
  // Versions dropped because their checksum did not match or their chunks disagreed.
  int64_t rejected() const { return rejected_; }
  // Versions refused at their first chunk, before any allocation: an architecture the receiver
  // refuses, a total size other than its network's, or more chunks than floats. Counted once per
  // version (its later chunks are refused again, not counted again).
  int64_t refused() const { return refused_; }

 private:
  struct Partial {
    std::string architecture;
    std::vector<float> params;
    std::vector<bool> have;
    int received = 0;
    int64_t crc32 = 0;
  };

  // Whether a version starting with `chunk` is one the receiver could use.
  bool Plausible(const rlmsg::weights_chunk_t& chunk);

  SizeOf size_of_;
  std::optional<std::string> sized_architecture_;  // the last architecture asked about
  int64_t sized_floats_ = -1;                      // and its answer
  std::map<int64_t, Partial> partial_;             // by version
  std::optional<Weights> ready_;
  int64_t complete_version_ = -1;
  int64_t rejected_ = 0;
  int64_t refused_ = 0;
  int64_t last_refused_version_ = -1;
};

}  // namespace rl::actor
