#include "nn/checkpoint.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <bit>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <random>
#include <stdexcept>

#include "common/atomic_file.h"
#include "common/crc32.h"
#include "nn/sequential.h"

namespace rl::nn {
namespace {

static_assert(std::endian::native == std::endian::little,
              "checkpoint files are little-endian; add byte swapping for this platform");

constexpr char kMagic[8] = {'R', 'L', 'C', 'K', 'P', 'T', '0', '1'};
constexpr uint32_t kVersion = 1;
// Magic, version and file size: enough to decide whether and how to read the rest.
constexpr size_t kPrefixSize = sizeof(kMagic) + sizeof(uint32_t) + sizeof(uint64_t);
constexpr size_t kCrcSize = sizeof(uint32_t);

class Writer {
 public:
  template <typename T>
  void Put(T value) {
    const size_t at = bytes_.size();
    bytes_.resize(at + sizeof(T));
    std::memcpy(bytes_.data() + at, &value, sizeof(T));
  }
  void PutBytes(const void* data, size_t n) {
    if (n == 0) return;
    const size_t at = bytes_.size();
    bytes_.resize(at + n);
    std::memcpy(bytes_.data() + at, data, n);
  }
  void PutString(const std::string& s, const std::string& field) {
    if (s.size() > UINT32_MAX) {
      throw std::runtime_error("checkpoint " + field + " is too long (" + std::to_string(s.size()) +
                               " bytes)");
    }
    Put(static_cast<uint32_t>(s.size()));
    PutBytes(s.data(), s.size());
  }
  std::vector<char>& bytes() { return bytes_; }

 private:
  std::vector<char> bytes_;
};

// Reads fields of a byte range whose checksum has already been verified; a field that runs past
// the end means the writer was inconsistent, which we report as corruption.
class Reader {
 public:
  Reader(const char* data, size_t size, const std::string& path)
      : data_(data), size_(size), path_(path) {}

  template <typename T>
  T Get(const char* field) {
    T value;
    std::memcpy(&value, Take(sizeof(T), field), sizeof(T));
    return value;
  }
  std::string GetString(const char* field) {
    const auto n = Get<uint32_t>(field);
    const char* p = Take(n, field);
    return std::string(p, n);
  }
  const char* Take(uint64_t n, const char* field) {
    if (n > size_ - pos_) {
      throw std::runtime_error("checkpoint " + path_ + " is corrupted: field '" + field +
                               "' runs past the end of the data");
    }
    const char* p = data_ + pos_;
    pos_ += static_cast<size_t>(n);
    return p;
  }
  size_t remaining() const { return size_ - pos_; }

 private:
  const char* data_;
  size_t size_;
  size_t pos_ = 0;
  const std::string& path_;
};

std::string ErrnoText(int err) { return std::strerror(err); }

// Reads the whole file at `path`.
std::vector<char> ReadFile(const std::string& path) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) {
    const int err = errno;
    throw std::runtime_error("cannot open checkpoint " + path + ": " + ErrnoText(err));
  }
  std::vector<char> bytes;
  struct stat st {};
  if (::fstat(fd, &st) == 0 && st.st_size > 0) bytes.reserve(static_cast<size_t>(st.st_size));
  char buf[1 << 16];
  while (true) {
    const ssize_t got = ::read(fd, buf, sizeof(buf));
    if (got < 0 && errno == EINTR) continue;
    if (got < 0) {
      const int err = errno;
      ::close(fd);
      throw std::runtime_error("cannot read checkpoint " + path + ": " + ErrnoText(err));
    }
    if (got == 0) break;
    bytes.insert(bytes.end(), buf, buf + got);
  }
  ::close(fd);
  return bytes;
}

}  // namespace

void SaveCheckpoint(const std::string& path, const Checkpoint& ckpt) {
  // Serialise into memory; the file size field is patched once the size is known.
  Writer w;
  w.PutBytes(kMagic, sizeof(kMagic));
  w.Put(kVersion);
  w.Put(uint64_t{0});
  w.PutString(ckpt.architecture, "architecture");
  w.Put(ckpt.meta.update);
  w.Put(ckpt.meta.env_steps);
  w.Put(ckpt.meta.wall_seconds);
  w.Put(ckpt.meta.run_id);
  w.PutString(ckpt.meta.note, "note");
  w.Put(static_cast<uint64_t>(ckpt.params.size()));
  w.PutBytes(ckpt.params.data(), ckpt.params.size() * sizeof(float));
  std::vector<char>& bytes = w.bytes();
  const uint64_t file_size = bytes.size() + kCrcSize;
  std::memcpy(bytes.data() + sizeof(kMagic) + sizeof(uint32_t), &file_size, sizeof(file_size));
  const uint32_t crc = Crc32(bytes.data(), bytes.size());
  w.Put(crc);

  WriteFileAtomically(path, std::string_view(bytes.data(), bytes.size()), "checkpoint");
}

Checkpoint LoadCheckpoint(const std::string& path) {
  const std::vector<char> bytes = ReadFile(path);
  return ParseCheckpoint(std::string_view(bytes.data(), bytes.size()), path);
}

Checkpoint ParseCheckpoint(std::string_view bytes, const std::string& path) {
  auto fail = [&](const std::string& why) -> std::runtime_error {
    return std::runtime_error("checkpoint " + path + " " + why);
  };

  // Magic, version, size and checksum, in the order that gives the most useful message.
  if (bytes.empty()) throw fail("is truncated: the file is empty");
  const size_t magic_bytes = std::min(bytes.size(), sizeof(kMagic));
  if (std::memcmp(bytes.data(), kMagic, magic_bytes) != 0) {
    throw fail("is not a checkpoint file (bad magic)");
  }
  if (bytes.size() < kPrefixSize) {
    throw fail("is truncated: " + std::to_string(bytes.size()) + " bytes, not even a header");
  }
  uint32_t version = 0;
  std::memcpy(&version, bytes.data() + sizeof(kMagic), sizeof(version));
  if (version != kVersion) {
    throw fail("has unsupported format version " + std::to_string(version) + " (this build reads " +
               std::to_string(kVersion) + ")");
  }
  uint64_t file_size = 0;
  std::memcpy(&file_size, bytes.data() + sizeof(kMagic) + sizeof(uint32_t), sizeof(file_size));
  if (bytes.size() < file_size) {
    throw fail("is truncated: " + std::to_string(bytes.size()) + " of " +
               std::to_string(file_size) + " bytes");
  }
  if (bytes.size() > file_size || file_size < kPrefixSize + kCrcSize) {
    throw fail("is corrupted: header says " + std::to_string(file_size) + " bytes, file has " +
               std::to_string(bytes.size()));
  }
  const size_t body = bytes.size() - kCrcSize;
  uint32_t stored_crc = 0;
  std::memcpy(&stored_crc, bytes.data() + body, sizeof(stored_crc));
  const uint32_t crc = Crc32(bytes.data(), body);
  if (crc != stored_crc) throw fail("is corrupted: checksum mismatch");

  // The fields.
  Checkpoint ckpt;
  Reader r(bytes.data() + kPrefixSize, body - kPrefixSize, path);
  ckpt.architecture = r.GetString("architecture");
  ckpt.meta.update = r.Get<int64_t>("update");
  ckpt.meta.env_steps = r.Get<int64_t>("env_steps");
  ckpt.meta.wall_seconds = r.Get<double>("wall_seconds");
  ckpt.meta.run_id = r.Get<uint64_t>("run_id");
  ckpt.meta.note = r.GetString("note");
  const auto num_params = r.Get<uint64_t>("num_params");
  if (num_params > r.remaining() / sizeof(float)) {
    throw fail("is corrupted: " + std::to_string(num_params) + " parameters do not fit");
  }
  ckpt.params.resize(static_cast<size_t>(num_params));
  const char* floats = r.Take(num_params * sizeof(float), "params");
  if (num_params > 0) std::memcpy(ckpt.params.data(), floats, num_params * sizeof(float));
  if (r.remaining() != 0) {
    throw fail("is corrupted: " + std::to_string(r.remaining()) + " unexpected trailing bytes");
  }

  // The parameters (and buffers) must fit the architecture.
  std::mt19937 rng(0);
  int64_t expected = 0;
  try {
    expected = BuildFromArchitecture(ckpt.architecture, &rng).FlatSize();
  } catch (const std::invalid_argument& e) {
    throw fail(std::string("has an invalid architecture: ") + e.what());
  }
  if (static_cast<uint64_t>(expected) != num_params) {
    throw fail("holds " + std::to_string(num_params) + " parameters but " + ckpt.architecture +
               " has " + std::to_string(expected) + " (parameters and buffers)");
  }
  return ckpt;
}

std::string CheckpointFileName(int64_t update) {
  char name[64];
  std::snprintf(name, sizeof(name), "ckpt-%09lld.bin", static_cast<long long>(update));
  return name;
}

std::vector<std::string> CheckpointFilesIn(const std::string& dir) {
  std::vector<std::pair<int64_t, std::string>> found;
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator(dir, ec)) {
    const std::string name = entry.path().filename().string();
    constexpr std::string_view kPrefix = "ckpt-", kSuffix = ".bin";
    if (!name.starts_with(kPrefix) || !name.ends_with(kSuffix)) continue;
    const std::string digits =
        name.substr(kPrefix.size(), name.size() - kPrefix.size() - kSuffix.size());
    // Update counts of at most 18 digits (int64_t).
    if (digits.empty() || digits.size() > 18 ||
        digits.find_first_not_of("0123456789") != std::string::npos) {
      continue;
    }
    std::error_code regular;
    if (!entry.is_regular_file(regular)) continue;
    found.emplace_back(std::stoll(digits), entry.path().string());
  }
  std::sort(found.begin(), found.end());
  std::vector<std::string> files;
  files.reserve(found.size());
  for (auto& [update, path] : found) files.push_back(std::move(path));
  return files;
}

}  // namespace rl::nn
