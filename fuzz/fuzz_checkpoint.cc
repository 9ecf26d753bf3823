// Fuzz target: policy checkpoint files (nn/checkpoint.h) as the evaluator loads them:
// nn::LoadCheckpoint() from a file, then the network built from the checkpoint's architecture
// string and given its parameters. Each input is loaded as given and again with its size field
// and trailing CRC-32 made right, which takes mutations past the checksum to the field reader and
// the architecture parser. Contract checked: a bad file is refused with std::runtime_error.
#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>

#include "fuzz/fuzz_support.h"
#include "nn/checkpoint.h"

namespace {

void Load(const std::string& path) {
  try {
    rl::fuzz::BuildNetwork(rl::nn::LoadCheckpoint(path));
  } catch (const std::runtime_error&) {
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static rl::fuzz::MemFile file("checkpoint");
  std::string bytes(reinterpret_cast<const char*>(data), size);
  Load(file.Write(bytes));
  if (rl::fuzz::FixCheckpointSizeAndCrc(&bytes)) Load(file.Write(bytes));
  return 0;
}
