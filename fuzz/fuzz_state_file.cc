// Fuzz target: learner state files (common/state_file.h) as a restarted learner loads them:
// StateFile::Load() from a file, then the learner's and the algorithm's sections
// (learner/algorithm_state.h) for a DQN and a TD3 (learner_state.h). Each input is loaded as
// given (the checksum refuses nearly every mutation) and again with its last 4 bytes replaced by
// the right CRC-32, which takes mutations to the section parser and the loaders. Contract checked:
// a bad file is refused with std::runtime_error, nothing else escapes.
#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>

#include "common/state_file.h"
#include "fuzz/fuzz_support.h"
#include "fuzz/learner_state.h"

namespace {

void Load(const std::string& path) {
  for (rl::fuzz::FuzzLearner& l : rl::fuzz::FuzzLearners()) {
    try {
      const rl::StateFile state = rl::StateFile::Load(path, l.kind);
      rl::fuzz::LoadLearnerState(state, &l);
    } catch (const std::runtime_error&) {
    }
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static rl::fuzz::MemFile file("state_file");
  std::string bytes(reinterpret_cast<const char*>(data), size);
  Load(file.Write(bytes));
  if (bytes.size() >= 4) {
    rl::fuzz::FixCrc(&bytes);
    Load(file.Write(bytes));
  }
  return 0;
}
