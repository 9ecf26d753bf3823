// Fuzz target: replay snapshots as a restarted replay loads them: ReplayService::LoadSnapshot()
// (the file mapped, its sections checked against the service's configuration and restored) into
// a fresh service, then the restored service's first traffic (a few inserts, a sample, priority
// updates), so that a snapshot that loads but leaves the tables inconsistent shows up as a crash.
// Input: one byte selecting the service configuration (replay_setup.h), then the file. Each input
// is loaded as given and again with its last 4 bytes replaced by the right CRC-32. Contract
// checked: a bad snapshot is refused with std::runtime_error; nothing else escapes.
#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>

#include "fuzz/fuzz_support.h"
#include "fuzz/replay_setup.h"

namespace {

void Load(const std::string& path, int config) {
  rl::fuzz::Replica replica(config);
  try {
    replica.service().LoadSnapshot(path);
  } catch (const std::runtime_error&) {
    return;
  }
  replica.Fill(2, 2);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static rl::fuzz::MemFile file("snapshot");
  if (size == 0) return 0;
  const int config = data[0] % rl::fuzz::kNumReplayConfigs;
  std::string bytes(reinterpret_cast<const char*>(data) + 1, size - 1);
  Load(file.Write(bytes), config);
  if (bytes.size() >= 4) {
    rl::fuzz::FixCrc(&bytes);
    Load(file.Write(bytes), config);
  }
  return 0;
}
