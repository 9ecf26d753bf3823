// StateFile: a checksummed file of named sections (floats, doubles, 64-bit integers, bytes,
// text), written atomically. What a process needs to continue after a restart (the learner's
// networks, optimizer states, counters and generators; the replay's contents) goes into one; a
// torn, corrupted or foreign file is refused with a clear error, never half-loaded.
//
// Layout (little-endian, as the machines of a run are): "RLSTATE1", u32 kind length, kind,
// u32 section count, then per section: u8 type (1 floats, 2 int64s, 3 text, 4 bytes, 5 doubles),
// u32 name length, name, u64 byte length, bytes; then the CRC-32 (common/crc32.h) of everything
// before it.
//
// Three views of one format: StateFile owns its sections (small states, built and read whole);
// StateStream writes sections that stay in the caller's memory, without copying or allocating
// while it writes (large states, written by a fork()ed child); StateView parses bytes in place
// (a mapped file) without copying them.
#pragma once

#include <cstdint>
#include <deque>
#include <map>
#include <memory>
#include <set>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace rl {

class AtomicFileStream;

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
  /// refused (too short, bad magic, bad checksum, malformed sections, another kind, a type this
  /// class does not hold: bytes or doubles, which StateView reads).
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
  static StateFile FromView(const class StateView& view);

  std::string kind_;
  std::map<std::string, Section> sections_;
};

/// Writes a state file whose large sections stay in the caller's memory. Building it (the Add
/// and Put calls) allocates; Write() does not: it makes system calls only, takes no lock and
/// throws nothing, so a child of fork() may call it in a process with other threads. Sections
/// are written in the order they were added. Not copyable; not thread-safe.
class StateStream {
 public:
  /// Longest kind and section name (bytes).
  static constexpr size_t kMaxName = 256;

  /// Throws std::invalid_argument when the kind is longer than kMaxName.
  explicit StateStream(std::string kind);
  StateStream(const StateStream&) = delete;
  StateStream& operator=(const StateStream&) = delete;

  /// Adds a section that refers to `values` without copying them: they must stay valid and
  /// unchanged until Write() returns. A section may be made of several pieces (AddPiece appends
  /// one to the section added last, of the same type). Throws std::invalid_argument for a name
  /// used twice or longer than kMaxName.
  void AddFloats(const std::string& name, std::span<const float> values);
  void AddDoubles(const std::string& name, std::span<const double> values);
  void AddInts(const std::string& name, std::span<const int64_t> values);
  void AddBytes(const std::string& name, std::span<const uint8_t> values);
  void AddPiece(const void* data, size_t bytes);
  /// Adds a section holding a copy of small values (counters, text).
  void PutInts(const std::string& name, std::span<const int64_t> values);
  void PutInt(const std::string& name, int64_t value) { PutInts(name, {&value, 1}); }
  void PutDoubles(const std::string& name, std::span<const double> values);
  void PutText(const std::string& name, std::string_view text);

  /// Size of the file Write() produces, in bytes.
  int64_t size() const;
  /// Writes the file into `out` (opened, not committed). Returns false when a write fails (the
  /// reason is in `out`). O(size()); no allocation.
  bool Write(AtomicFileStream* out) const;
  /// The file's bytes (allocates), for tests and small states.
  std::string Serialize() const;

 private:
  struct Piece {
    const void* data;
    size_t bytes;
  };
  struct Section {
    uint8_t type = 0;
    std::string name;
    std::vector<Piece> pieces;
  };
  void Add(const std::string& name, uint8_t type, const void* data, size_t bytes);
  void Put(const std::string& name, uint8_t type, const void* data, size_t bytes);

  std::string kind_;
  std::vector<Section> sections_;
  std::set<std::string> names_;
  std::deque<std::string> owned_;  // copies made by Put (a deque: their addresses stay put)
};

/// A state file parsed in place: sections refer to the parsed bytes, which must outlive the
/// view unless the view maps them itself (Map). Parse checks what StateFile::Parse checks (magic,
/// CRC-32, kind, every section within the bytes, known types, lengths that are whole values, no
/// name twice) and throws std::runtime_error saying why bytes are refused. Its only allocations
/// are one map entry per section, bounded by the input's size.
class StateView {
 public:
  static StateView Parse(std::string_view bytes, const std::string& kind);
  /// Maps the file read-only and parses it; errors (also a file that cannot be read) are
  /// std::runtime_error "state <path> refused: <why>" or "cannot read state <path>: <why>".
  static StateView Map(const std::string& path, const std::string& kind);

  StateView(StateView&&) noexcept;
  StateView& operator=(StateView&&) noexcept;
  ~StateView();

  const std::string& kind() const { return kind_; }
  bool Has(const std::string& name) const { return sections_.count(name) != 0; }
  /// Values in section `name` of the type T (float, double, int64_t, uint8_t). Throws
  /// std::runtime_error naming the section when it is missing or of another type.
  template <class T>
  int64_t Count(const std::string& name) const;
  /// Copies section `name` into `out`, which must have exactly its number of values (otherwise
  /// std::runtime_error naming the section and both lengths). O(bytes).
  template <class T>
  void Copy(const std::string& name, std::span<T> out) const;
  /// A copy of an int64 section of at most `max_count` values (std::runtime_error beyond).
  std::vector<int64_t> Ints(const std::string& name, int64_t max_count) const;
  int64_t Int(const std::string& name) const;
  std::string Text(const std::string& name) const;
  /// Bytes of the whole file.
  int64_t size() const { return static_cast<int64_t>(bytes_.size()); }

 private:
  struct Mapping;
  struct Section {
    uint8_t type = 0;
    std::string_view data;
  };
  friend class StateFile;
  StateView() = default;
  const Section& Get(const std::string& name, uint8_t type) const;

  std::unique_ptr<Mapping> mapping_;
  std::string_view bytes_;
  std::string kind_;
  std::map<std::string, Section, std::less<>> sections_;
};

}  // namespace rl
