#include "fuzz/fuzz_support.h"

#include <sys/mman.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <random>

#include "common/crc32.h"
#include "nn/sequential.h"

namespace rl::fuzz {

MemFile::MemFile(const char* name) : fd_(memfd_create(name, MFD_CLOEXEC)) {
  if (fd_ < 0) {
    std::perror("memfd_create");
    std::abort();
  }
  path_ = "/proc/self/fd/" + std::to_string(fd_);
}

MemFile::~MemFile() { close(fd_); }

const std::string& MemFile::Write(std::string_view bytes) {
  if (ftruncate(fd_, 0) != 0) std::abort();
  size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n =
        pwrite(fd_, bytes.data() + done, bytes.size() - done, static_cast<off_t>(done));
    if (n <= 0) std::abort();
    done += static_cast<size_t>(n);
  }
  return path_;
}

std::vector<std::string_view> Records(const uint8_t* data, size_t size) {
  std::vector<std::string_view> records;
  size_t at = 0;
  while (at + 2 <= size && records.size() < 64) {
    const size_t length = std::min<size_t>(data[at] | (size_t{data[at + 1]} << 8), size - at - 2);
    records.emplace_back(reinterpret_cast<const char*>(data) + at + 2, length);
    at += 2 + length;
  }
  return records;
}

void AppendRecord(std::string* input, std::string_view bytes) {
  if (bytes.size() > 0xFFFF) {
    std::fprintf(stderr, "fuzz: a record of %zu bytes does not fit a 2-byte length\n",
                 bytes.size());
    std::abort();
  }
  input->push_back(static_cast<char>(bytes.size() & 0xFF));
  input->push_back(static_cast<char>(bytes.size() >> 8));
  input->append(bytes);
}

bool FixCheckpointSizeAndCrc(std::string* bytes) {
  // The u64 file size comes after the 8-byte magic and the u32 version.
  constexpr size_t kSizeField = 12;
  if (bytes->size() < kSizeField + sizeof(uint64_t) + 4) return false;
  const uint64_t file_size = bytes->size();
  std::memcpy(bytes->data() + kSizeField, &file_size, sizeof(file_size));
  FixCrc(bytes);
  return true;
}

void BuildNetwork(const nn::Checkpoint& checkpoint) {
  std::mt19937 rng(0);
  nn::Sequential net = nn::BuildFromArchitecture(checkpoint.architecture, &rng);
  net.SetFlat(checkpoint.params.data(), checkpoint.params.size());
}

void FixCrc(std::string* bytes) {
  if (bytes->size() < 4) return;
  const size_t body = bytes->size() - 4;
  const uint32_t crc = Crc32(bytes->data(), body);
  std::memcpy(bytes->data() + body, &crc, sizeof(crc));
}

}  // namespace rl::fuzz
