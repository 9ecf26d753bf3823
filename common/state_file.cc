#include "common/state_file.h"

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <stdexcept>
#include <type_traits>

#include "common/atomic_file.h"
#include "common/crc32.h"

namespace rl {
namespace {

constexpr char kMagic[] = "RLSTATE1";
constexpr size_t kMagicSize = 8;
constexpr uint8_t kFloats = 1, kInts = 2, kText = 3, kBytes = 4, kDoubles = 5;

template <class T>
void Append(std::string* out, T value) {
  out->append(reinterpret_cast<const char*>(&value), sizeof(T));
}

// The section type of an array of T.
template <class T>
constexpr uint8_t TypeOf() {
  static_assert(std::is_same_v<T, float> || std::is_same_v<T, int64_t> ||
                std::is_same_v<T, uint8_t> || std::is_same_v<T, double>);
  if constexpr (std::is_same_v<T, float>) return kFloats;
  if constexpr (std::is_same_v<T, int64_t>) return kInts;
  if constexpr (std::is_same_v<T, uint8_t>) return kBytes;
  return kDoubles;
}

// Bytes per value of a section type, or 0 for an unknown type.
size_t ValueSize(uint8_t type) {
  switch (type) {
    case kFloats:
      return sizeof(float);
    case kInts:
    case kDoubles:
      return 8;
    case kText:
    case kBytes:
      return 1;
    default:
      return 0;
  }
}

// Reads the parts of a file in order, refusing to read past its end.
class Cursor {
 public:
  explicit Cursor(std::string_view bytes) : bytes_(bytes) {}
  template <class T>
  T Read() {
    T value;
    std::memcpy(&value, Take(sizeof(T)).data(), sizeof(T));
    return value;
  }
  std::string_view Take(uint64_t n) {
    if (n > bytes_.size() - at_)
      throw std::runtime_error("truncated (a section runs past the end)");
    const std::string_view part = bytes_.substr(at_, n);
    at_ += n;
    return part;
  }
  bool done() const { return at_ == bytes_.size(); }

 private:
  std::string_view bytes_;
  size_t at_ = 0;
};

// The section `name` of a map of sections by name (StateFile's or StateView's); throws
// std::runtime_error if there is none or it holds another type.
template <class Sections>
const typename Sections::mapped_type& SectionOfType(const Sections& sections,
                                                    const std::string& name, uint8_t type) {
  const auto it = sections.find(name);
  if (it == sections.end()) throw std::runtime_error("state has no section '" + name + "'");
  if (it->second.type != type) {
    throw std::runtime_error("state section '" + name + "' has another type");
  }
  return it->second;
}

}  // namespace

// ---------------------------------------------------------------------------------- StateFile

StateFile::Section& StateFile::Add(const std::string& name, uint8_t type) {
  if (sections_.count(name) != 0) {
    throw std::invalid_argument("state section '" + name + "' written twice");
  }
  Section& s = sections_[name];
  s.type = type;
  return s;
}

void StateFile::PutFloats(const std::string& name, std::span<const float> values) {
  Add(name, kFloats).floats.assign(values.begin(), values.end());
}

void StateFile::PutInts(const std::string& name, std::span<const int64_t> values) {
  Add(name, kInts).ints.assign(values.begin(), values.end());
}

void StateFile::PutText(const std::string& name, std::string_view text) {
  Add(name, kText).text = std::string(text);
}

const StateFile::Section& StateFile::Get(const std::string& name, uint8_t type) const {
  return SectionOfType(sections_, name, type);
}

std::span<const float> StateFile::Floats(const std::string& name, int64_t expected) const {
  const std::vector<float>& v = Get(name, kFloats).floats;
  if (expected >= 0 && static_cast<int64_t>(v.size()) != expected) {
    throw std::runtime_error("state section '" + name + "' holds " + std::to_string(v.size()) +
                             " values, expected " + std::to_string(expected));
  }
  return v;
}

std::span<const int64_t> StateFile::Ints(const std::string& name) const {
  return Get(name, kInts).ints;
}

int64_t StateFile::Int(const std::string& name) const {
  const std::span<const int64_t> v = Ints(name);
  if (v.size() != 1) throw std::runtime_error("state section '" + name + "' is not one integer");
  return v[0];
}

const std::string& StateFile::Text(const std::string& name) const { return Get(name, kText).text; }

std::string StateFile::Serialize() const {
  std::string out(kMagic, kMagicSize);
  Append<uint32_t>(&out, static_cast<uint32_t>(kind_.size()));
  out += kind_;
  Append<uint32_t>(&out, static_cast<uint32_t>(sections_.size()));
  for (const auto& [name, s] : sections_) {
    Append<uint8_t>(&out, s.type);
    Append<uint32_t>(&out, static_cast<uint32_t>(name.size()));
    out += name;
    const char* data = s.type == kFloats ? reinterpret_cast<const char*>(s.floats.data())
                       : s.type == kInts ? reinterpret_cast<const char*>(s.ints.data())
                                         : s.text.data();
    const uint64_t size = s.type == kFloats ? s.floats.size() * sizeof(float)
                          : s.type == kInts ? s.ints.size() * sizeof(int64_t)
                                            : s.text.size();
    Append<uint64_t>(&out, size);
    out.append(data, size);
  }
  Append<uint32_t>(&out, Crc32(out.data(), out.size()));
  return out;
}

StateFile StateFile::Parse(std::string_view bytes, const std::string& kind) {
  return FromView(StateView::Parse(bytes, kind));
}

StateFile StateFile::FromView(const StateView& view) {
  StateFile state(view.kind());
  // Every section, in the view's (name) order; the view has checked lengths and types.
  for (const auto& [name, s] : view.sections_) {
    // Copy() handles empty sections (an empty vector's data() may be null, never memcpy's).
    if (s.type == kFloats) {
      std::vector<float> v(s.data.size() / sizeof(float));
      view.Copy<float>(name, v);
      state.PutFloats(name, v);
    } else if (s.type == kInts) {
      std::vector<int64_t> v(s.data.size() / sizeof(int64_t));
      view.Copy<int64_t>(name, v);
      state.PutInts(name, v);
    } else if (s.type == kText) {
      state.PutText(name, s.data);
    } else {
      throw std::runtime_error("section '" + name + "' is of a type StateFile does not hold");
    }
  }
  return state;
}

void StateFile::Save(const std::string& path) const {
  WriteFileAtomically(path, Serialize(), "state");
}

StateFile StateFile::Load(const std::string& path, const std::string& kind) {
  const StateView view = StateView::Map(path, kind);
  try {
    return FromView(view);
  } catch (const std::exception& e) {
    throw std::runtime_error("state " + path + " refused: " + e.what());
  }
}

// -------------------------------------------------------------------------------- StateStream

StateStream::StateStream(std::string kind) : kind_(std::move(kind)) {
  if (kind_.size() > kMaxName) throw std::invalid_argument("state kind longer than 256 bytes");
}

void StateStream::Add(const std::string& name, uint8_t type, const void* data, size_t bytes) {
  if (name.size() > kMaxName) {
    throw std::invalid_argument("state section name longer than 256 bytes: " + name);
  }
  if (!names_.insert(name).second) {
    throw std::invalid_argument("state section '" + name + "' written twice");
  }
  Section s;
  s.type = type;
  s.name = name;
  if (bytes > 0) s.pieces.push_back(Piece{data, bytes});
  sections_.push_back(std::move(s));
}

void StateStream::Put(const std::string& name, uint8_t type, const void* data, size_t bytes) {
  owned_.emplace_back(static_cast<const char*>(data), bytes);
  Add(name, type, owned_.back().data(), bytes);
}

void StateStream::AddFloats(const std::string& name, std::span<const float> values) {
  Add(name, kFloats, values.data(), values.size_bytes());
}
void StateStream::AddDoubles(const std::string& name, std::span<const double> values) {
  Add(name, kDoubles, values.data(), values.size_bytes());
}
void StateStream::AddInts(const std::string& name, std::span<const int64_t> values) {
  Add(name, kInts, values.data(), values.size_bytes());
}
void StateStream::AddBytes(const std::string& name, std::span<const uint8_t> values) {
  Add(name, kBytes, values.data(), values.size_bytes());
}
void StateStream::AddPiece(const void* data, size_t bytes) {
  if (sections_.empty()) throw std::invalid_argument("AddPiece before any section");
  if (bytes > 0) sections_.back().pieces.push_back(Piece{data, bytes});
}
void StateStream::PutInts(const std::string& name, std::span<const int64_t> values) {
  Put(name, kInts, values.data(), values.size_bytes());
}
void StateStream::PutDoubles(const std::string& name, std::span<const double> values) {
  Put(name, kDoubles, values.data(), values.size_bytes());
}
void StateStream::PutText(const std::string& name, std::string_view text) {
  Put(name, kText, text.data(), text.size());
}

int64_t StateStream::size() const {
  uint64_t n = kMagicSize + 4 + kind_.size() + 4;
  for (const Section& s : sections_) {
    n += 1 + 4 + s.name.size() + 8;
    for (const Piece& p : s.pieces) n += p.bytes;
  }
  return static_cast<int64_t>(n + 4);
}

namespace {

// Writes through an AtomicFileStream, or appends to a string, keeping the CRC-32 of it all.
// Chunks of large pieces alternate checksum and write, so both stay in the cache.
class Sink {
 public:
  explicit Sink(AtomicFileStream* file) : file_(file) {}
  explicit Sink(std::string* bytes) : bytes_(bytes) {}
  bool Put(const void* data, size_t n) {
    constexpr size_t kChunk = size_t{1} << 20;
    const auto* p = static_cast<const char*>(data);
    for (size_t done = 0; done < n;) {
      const size_t k = std::min(kChunk, n - done);
      crc_ = Crc32(p + done, k, crc_);
      if (file_ != nullptr) {
        if (!file_->Write(p + done, k)) return false;
      } else {
        bytes_->append(p + done, k);
      }
      done += k;
    }
    return true;
  }
  template <class T>
  bool PutValue(T value) {
    return Put(&value, sizeof(T));
  }
  bool Finish() {
    const uint32_t crc = crc_;
    return file_ != nullptr ? file_->Write(&crc, 4)
                            : (bytes_->append(reinterpret_cast<const char*>(&crc), 4), true);
  }

 private:
  AtomicFileStream* file_ = nullptr;
  std::string* bytes_ = nullptr;
  uint32_t crc_ = 0;
};

// The layout, written through a Sink. No allocation when the sink writes to a file.
template <class Sections>
bool WriteLayout(const std::string& kind, const Sections& sections, Sink* out) {
  if (!out->Put(kMagic, kMagicSize) ||
      !out->PutValue<uint32_t>(static_cast<uint32_t>(kind.size())) ||
      !out->Put(kind.data(), kind.size()) ||
      !out->PutValue<uint32_t>(static_cast<uint32_t>(sections.size()))) {
    return false;
  }
  for (const auto& s : sections) {
    uint64_t bytes = 0;
    for (const auto& p : s.pieces) bytes += p.bytes;
    if (!out->PutValue<uint8_t>(s.type) ||
        !out->PutValue<uint32_t>(static_cast<uint32_t>(s.name.size())) ||
        !out->Put(s.name.data(), s.name.size()) || !out->PutValue<uint64_t>(bytes)) {
      return false;
    }
    for (const auto& p : s.pieces) {
      if (!out->Put(p.data, p.bytes)) return false;
    }
  }
  return out->Finish();
}

}  // namespace

bool StateStream::Write(AtomicFileStream* out) const {
  Sink sink(out);
  return WriteLayout(kind_, sections_, &sink);
}

std::string StateStream::Serialize() const {
  std::string bytes;
  bytes.reserve(static_cast<size_t>(size()));
  Sink sink(&bytes);
  WriteLayout(kind_, sections_, &sink);
  return bytes;
}

// ---------------------------------------------------------------------------------- StateView

struct StateView::Mapping {
  void* data = nullptr;
  size_t size = 0;
  ~Mapping() {
    if (data != nullptr) ::munmap(data, size);
  }
};

StateView::StateView(StateView&&) noexcept = default;
StateView& StateView::operator=(StateView&&) noexcept = default;
StateView::~StateView() = default;

StateView StateView::Parse(std::string_view bytes, const std::string& kind) {
  if (bytes.size() < kMagicSize + 4 || bytes.substr(0, kMagicSize) != kMagic) {
    throw std::runtime_error("not a state file (bad magic or too short)");
  }
  const std::string_view body = bytes.substr(0, bytes.size() - 4);
  uint32_t stored = 0;
  std::memcpy(&stored, bytes.data() + body.size(), 4);
  if (Crc32(body.data(), body.size()) != stored) {
    throw std::runtime_error("checksum mismatch (torn or corrupted file)");
  }
  Cursor c(body.substr(kMagicSize));
  StateView view;
  view.bytes_ = bytes;
  view.kind_ = std::string(c.Take(c.Read<uint32_t>()));
  if (view.kind_ != kind) {
    throw std::runtime_error("a state of '" + view.kind_ + "', expected '" + kind + "'");
  }
  const uint32_t count = c.Read<uint32_t>();
  for (uint32_t k = 0; k < count; ++k) {
    const auto type = c.Read<uint8_t>();
    const std::string_view name = c.Take(c.Read<uint32_t>());
    const std::string_view data = c.Take(c.Read<uint64_t>());
    const size_t value_size = ValueSize(type);
    if (value_size == 0 || data.size() % value_size != 0) {
      throw std::runtime_error("malformed section '" + std::string(name) + "'");
    }
    if (!view.sections_.emplace(std::string(name), Section{type, data}).second) {
      throw std::runtime_error("section '" + std::string(name) + "' appears twice");
    }
  }
  if (!c.done()) throw std::runtime_error("bytes after the last section");
  return view;
}

StateView StateView::Map(const std::string& path, const std::string& kind) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) throw std::runtime_error("cannot read state " + path + ": " + std::strerror(errno));
  struct stat st {};
  if (::fstat(fd, &st) != 0) {
    const int err = errno;
    ::close(fd);
    throw std::runtime_error("cannot read state " + path + ": " + std::strerror(err));
  }
  auto mapping = std::make_unique<Mapping>();
  if (st.st_size > 0) {
    mapping->size = static_cast<size_t>(st.st_size);
    void* data = ::mmap(nullptr, mapping->size, PROT_READ, MAP_PRIVATE, fd, 0);
    if (data == MAP_FAILED) {
      const int err = errno;
      ::close(fd);
      throw std::runtime_error("cannot read state " + path + ": " + std::strerror(err));
    }
    mapping->data = data;
    ::madvise(data, mapping->size, MADV_SEQUENTIAL);
  }
  ::close(fd);
  const std::string_view bytes(static_cast<const char*>(mapping->data), mapping->size);
  try {
    StateView view = Parse(bytes, kind);
    view.mapping_ = std::move(mapping);
    return view;
  } catch (const std::exception& e) {
    throw std::runtime_error("state " + path + " refused: " + e.what());
  }
}

const StateView::Section& StateView::Get(const std::string& name, uint8_t type) const {
  return SectionOfType(sections_, name, type);
}

template <class T>
int64_t StateView::Count(const std::string& name) const {
  return static_cast<int64_t>(Get(name, TypeOf<T>()).data.size() / sizeof(T));
}

template <class T>
void StateView::Copy(const std::string& name, std::span<T> out) const {
  const std::string_view data = Get(name, TypeOf<T>()).data;
  if (data.size() != out.size_bytes()) {
    throw std::runtime_error("state section '" + name + "' holds " +
                             std::to_string(data.size() / sizeof(T)) + " values, expected " +
                             std::to_string(out.size()));
  }
  if (!out.empty()) std::memcpy(out.data(), data.data(), data.size());
}

template int64_t StateView::Count<float>(const std::string&) const;
template int64_t StateView::Count<double>(const std::string&) const;
template int64_t StateView::Count<int64_t>(const std::string&) const;
template int64_t StateView::Count<uint8_t>(const std::string&) const;
template void StateView::Copy<float>(const std::string&, std::span<float>) const;
template void StateView::Copy<double>(const std::string&, std::span<double>) const;
template void StateView::Copy<int64_t>(const std::string&, std::span<int64_t>) const;
template void StateView::Copy<uint8_t>(const std::string&, std::span<uint8_t>) const;

std::vector<int64_t> StateView::Ints(const std::string& name, int64_t max_count) const {
  const int64_t n = Count<int64_t>(name);
  if (n > max_count) {
    throw std::runtime_error("state section '" + name + "' holds " + std::to_string(n) +
                             " values, at most " + std::to_string(max_count) + " expected");
  }
  std::vector<int64_t> values(static_cast<size_t>(n));
  Copy<int64_t>(name, values);
  return values;
}

int64_t StateView::Int(const std::string& name) const {
  int64_t value = 0;
  if (Count<int64_t>(name) != 1) {
    throw std::runtime_error("state section '" + name + "' is not one integer");
  }
  Copy<int64_t>(name, {&value, 1});
  return value;
}

std::string StateView::Text(const std::string& name) const {
  return std::string(Get(name, kText).data);
}

}  // namespace rl
