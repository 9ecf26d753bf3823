// Fuzz target: policy checkpoint files (nn/checkpoint.h) as the evaluator loads them:
// nn::LoadCheckpoint() from a file, then the network built from the checkpoint's architecture
// string and given its parameters. Each input is loaded as given and again with its size field
// and trailing CRC-32 made right, which takes mutations past the checksum to the field reader and
// the architecture parser. Contract checked: a bad file is refused with std::runtime_error.
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <random>
#include <stdexcept>
#include <string>

#include "fuzz/fuzz_support.h"
#include "nn/checkpoint.h"
#include "nn/sequential.h"

namespace {

// Offset of the u64 file size: after the 8-byte magic and the u32 version.
constexpr size_t kSizeField = 12;

void Load(const std::string& path) {
  try {
    const rl::nn::Checkpoint ckpt = rl::nn::LoadCheckpoint(path);
    std::mt19937 rng(0);
    rl::nn::Sequential net = rl::nn::BuildFromArchitecture(ckpt.architecture, &rng);
    net.SetFlat(ckpt.params.data(), ckpt.params.size());
  } catch (const std::runtime_error&) {
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static rl::fuzz::MemFile file("checkpoint");
  std::string bytes(reinterpret_cast<const char*>(data), size);
  Load(file.Write(bytes));
  if (bytes.size() >= kSizeField + sizeof(uint64_t) + 4) {
    const uint64_t file_size = bytes.size();
    std::memcpy(bytes.data() + kSizeField, &file_size, sizeof(file_size));
    rl::fuzz::FixCrc(&bytes);
    Load(file.Write(bytes));
  }
  return 0;
}
