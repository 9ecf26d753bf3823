#include "fuzz/fuzz_support.h"

#include <sys/mman.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>

#include "common/crc32.h"

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

void FixCrc(std::string* bytes) {
  if (bytes->size() < 4) return;
  const size_t body = bytes->size() - 4;
  const uint32_t crc = Crc32(bytes->data(), body);
  std::memcpy(bytes->data() + body, &crc, sizeof(crc));
}

}  // namespace rl::fuzz
