// Helpers shared by the fuzz targets and the seed writer (fuzz_seeds.cc).
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <iterator>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "common/clock.h"
#include "common/lcm_bus.h"
#include "common/messages.h"
#include "nn/checkpoint.h"

namespace rl::fuzz {

/// A file in memory (memfd_create) that the loaders open by path, so that they are fuzzed as the
/// processes call them: from a file name, with no disk I/O. One per target, reused.
class MemFile {
 public:
  /// `name` is for debugging only. Aborts when no memfd can be created.
  explicit MemFile(const char* name);
  ~MemFile();
  MemFile(const MemFile&) = delete;
  MemFile& operator=(const MemFile&) = delete;

  /// Replaces the file's content with `bytes`; returns the path to open ("/proc/self/fd/N").
  const std::string& Write(std::string_view bytes);

 private:
  int fd_ = -1;
  std::string path_;
};

/// The records of a handler target's input (after its selector byte): each a 2-byte
/// little-endian length, then as many bytes (the last one may be cut short by the input's end).
/// At most 64 records.
std::vector<std::string_view> Records(const uint8_t* data, size_t size);

/// Appends `bytes` to `input` as one record (the seed writer's side of Records()).
void AppendRecord(std::string* input, std::string_view bytes);

/// Publishes `bytes` on `channel` of `bus` (on its port: Bus::PublishRaw) as a message of type Msg
/// from `sender` arrives, and lets the bus dispatch it. When the bytes decode, their header is
/// replaced by a valid one of the bus's run (`*seq` as sequence number, then incremented; the
/// current time; incarnation 1; no MAC, the bus having no key), so that the fuzzed fields get past
/// the header checks to the handler; otherwise the bytes go as they are (and the bus drops them).
template <class Msg>
void Deliver(Bus* bus, const std::string& channel, std::string_view bytes,
             const std::string& sender, int64_t* seq, std::optional<Port> port = std::nullopt) {
  Msg m{};
  if (Decode(reinterpret_cast<const uint8_t*>(bytes.data()), bytes.size(), &m) != nullptr) {
    bus->PublishRaw(channel, bytes.data(), bytes.size(), port);
  } else {
    m.header.run_id = bus->config().run_id;
    m.header.sender = sender;
    m.header.seq = (*seq)++;
    m.header.utime = WallMicros();
    m.header.incarnation = 1;
    std::fill(std::begin(m.header.mac), std::end(m.header.mac), 0);
    std::vector<uint8_t> encoded(static_cast<size_t>(m.getEncodedSize()));
    m.encode(encoded.data(), 0, static_cast<int>(encoded.size()));
    bus->PublishRaw(channel, encoded.data(), encoded.size(), port);
  }
  bus->Handle(0);
}

/// A policy checkpoint file's bytes with its size field and CRC-32 made right, so that mutations
/// get past the loader's checks to its field reader and the architecture parser; false (bytes
/// unchanged) when they are too short to hold them.
bool FixCheckpointSizeAndCrc(std::string* bytes);

/// The network a loaded checkpoint describes, built and given its parameters, as the evaluator
/// and the actors build it. Throws as nn::BuildFromArchitecture and Sequential::SetFlat do.
void BuildNetwork(const nn::Checkpoint& checkpoint);

/// Overwrites the last 4 bytes of `bytes` with the CRC-32 (common/crc32.h) of the bytes before
/// them, so that mutated inputs get past a loader's checksum to its parser. No-op below 4 bytes.
void FixCrc(std::string* bytes);

}  // namespace rl::fuzz
