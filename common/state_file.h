// StateFile: a checksummed file of named sections (floats, 64-bit integers, text), written
// atomically. What a process needs to continue after a restart (the learner's networks,
// optimizer states, counters and generators) goes into one; a torn, corrupted or foreign file is
// refused with a clear error, never half-loaded.
//
// Layout (little-endian, as the machines of a run are): "RLSTATE1", u32 kind length, kind,
// u32 section count, then per section: u8 type (1 floats, 2 int64s, 3 text), u32 name length,
// name, u64 byte length, bytes; then the CRC-32 (common/crc32.h) of everything before it.
#pragma once

#include <cstdint>
#include <map>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace rl {

class StateFile {
 public:
  /// An empty state of `kind` (e.g. "learner td3"); Load() refuses a file of another kind.
  explicit StateFile(std::string kind) : kind_(std::move(kind)) {}

  const std::string& kind() const { return kind_; }

  /// Adds a section (a name may be used once: std::invalid_argument otherwise). Copies.
  void PutFloats(const std::string& name, std::span<const float> values);
  void PutInts(const std::string& name, std::span<const int64_t> values);
  void PutText(const std::string& name, std::string_view text);
  void PutInt(const std::string& name, int64_t value) { PutInts(name, {&value, 1}); }

  /// The section `name`, of its type. Throws std::runtime_error naming the section when it is
  /// missing or of another type, or (Floats with expected >= 0) of another length.
  std::span<const float> Floats(const std::string& name, int64_t expected = -1) const;
  std::span<const int64_t> Ints(const std::string& name) const;
  int64_t Int(const std::string& name) const;
  const std::string& Text(const std::string& name) const;
  bool Has(const std::string& name) const { return sections_.count(name) != 0; }

  /// The file's bytes, and the inverse: Parse throws std::runtime_error saying why the bytes are
  /// refused (too short, bad magic, bad checksum, malformed sections, another kind).
  std::string Serialize() const;
  static StateFile Parse(std::string_view bytes, const std::string& kind);

  /// Serialize() written with WriteFileAtomically; Load reads and Parses, naming the path in
  /// every error (std::runtime_error, also when the file cannot be read).
  void Save(const std::string& path) const;
  static StateFile Load(const std::string& path, const std::string& kind);

 private:
  struct Section {
    uint8_t type = 0;
    std::vector<float> floats;
    std::vector<int64_t> ints;
    std::string text;
  };
  Section& Add(const std::string& name, uint8_t type);
  const Section& Get(const std::string& name, uint8_t type) const;

  std::string kind_;
  std::map<std::string, Section> sections_;
};

}  // namespace rl
