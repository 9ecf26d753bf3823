// Helpers shared by the fuzz targets and the seed writer (fuzz_seeds.cc).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

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

/// Overwrites the last 4 bytes of `bytes` with the CRC-32 (common/crc32.h) of the bytes before
/// them, so that mutated inputs get past a loader's checksum to its parser. No-op below 4 bytes.
void FixCrc(std::string* bytes);

}  // namespace rl::fuzz
