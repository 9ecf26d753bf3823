#include "common/state_file.h"

#include <cstring>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "common/atomic_file.h"
#include "common/crc32.h"

namespace rl {
namespace {

constexpr char kMagic[] = "RLSTATE1";
constexpr size_t kMagicSize = 8;
constexpr uint8_t kFloats = 1, kInts = 2, kText = 3;

template <class T>
void Append(std::string* out, T value) {
  out->append(reinterpret_cast<const char*>(&value), sizeof(T));
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

}  // namespace

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
  const auto it = sections_.find(name);
  if (it == sections_.end()) throw std::runtime_error("state has no section '" + name + "'");
  if (it->second.type != type) {
    throw std::runtime_error("state section '" + name + "' has another type");
  }
  return it->second;
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
  const std::string file_kind(c.Take(c.Read<uint32_t>()));
  if (file_kind != kind) {
    throw std::runtime_error("a state of '" + file_kind + "', expected '" + kind + "'");
  }
  StateFile state(file_kind);
  const uint32_t count = c.Read<uint32_t>();
  for (uint32_t k = 0; k < count; ++k) {
    const auto type = c.Read<uint8_t>();
    const std::string name(c.Take(c.Read<uint32_t>()));
    const std::string_view data = c.Take(c.Read<uint64_t>());
    if (type == kFloats && data.size() % sizeof(float) == 0) {
      std::vector<float> v(data.size() / sizeof(float));
      std::memcpy(v.data(), data.data(), data.size());
      state.PutFloats(name, v);
    } else if (type == kInts && data.size() % sizeof(int64_t) == 0) {
      std::vector<int64_t> v(data.size() / sizeof(int64_t));
      std::memcpy(v.data(), data.data(), data.size());
      state.PutInts(name, v);
    } else if (type == kText) {
      state.PutText(name, data);
    } else {
      throw std::runtime_error("malformed section '" + name + "'");
    }
  }
  if (!c.done()) throw std::runtime_error("bytes after the last section");
  return state;
}

void StateFile::Save(const std::string& path) const {
  WriteFileAtomically(path, Serialize(), "state");
}

StateFile StateFile::Load(const std::string& path, const std::string& kind) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error("cannot read state " + path);
  std::ostringstream bytes;
  bytes << in.rdbuf();
  try {
    return Parse(bytes.str(), kind);
  } catch (const std::exception& e) {
    throw std::runtime_error("state " + path + " refused: " + e.what());
  }
}

}  // namespace rl
