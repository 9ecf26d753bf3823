#include "common/atomic_file.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <stdexcept>

namespace rl {
namespace {

std::string DirectoryOf(const std::string& path) {
  const size_t slash = path.rfind('/');
  if (slash == std::string::npos) return ".";
  if (slash == 0) return "/";
  return path.substr(0, slash);
}

// Fsyncs a directory so that a rename in it survives a crash. Some file systems cannot fsync a
// directory (EINVAL); the data is in place by then, so only real I/O errors count. Returns the
// failed step or nullptr (errno set). System calls only.
const char* SyncDirectory(const char* dir) {
  const int dir_fd = ::open(dir, O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (dir_fd < 0) return "open directory";
  if (::fsync(dir_fd) != 0 && errno != EINVAL) {
    const int err = errno;
    ::close(dir_fd);
    errno = err;
    return "sync directory";
  }
  ::close(dir_fd);
  return nullptr;
}

}  // namespace

std::string TemporaryPathFor(const std::string& path) {
  return path + ".tmp." + std::to_string(::getpid());
}

AtomicFileStream::AtomicFileStream(std::string path)
    : path_(std::move(path)), dir_(DirectoryOf(path_)) {
  const std::string stem = path_ + ".tmp.";
  tmp_stem_ = stem.size();
  tmp_.assign(stem.size() + 24, '\0');
  std::memcpy(tmp_.data(), stem.data(), stem.size());
}

AtomicFileStream::~AtomicFileStream() {
  if (fd_ >= 0) ::close(fd_);
  if (open_) ::unlink(tmp_.data());
}

bool AtomicFileStream::Fail(const char* step, int err, bool remove) {
  step_ = step;
  error_ = err;
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
  if (remove && open_) ::unlink(tmp_.data());
  open_ = false;
  return false;
}

bool AtomicFileStream::Open() {
  // The pid's digits after the stem, without allocating.
  char digits[24];
  int n = 0;
  for (auto pid = static_cast<unsigned long>(::getpid()); n == 0 || pid > 0; pid /= 10) {
    digits[n++] = static_cast<char>('0' + pid % 10);
  }
  for (int k = 0; k < n; ++k) tmp_[tmp_stem_ + static_cast<size_t>(k)] = digits[n - 1 - k];
  tmp_[tmp_stem_ + static_cast<size_t>(n)] = '\0';
  fd_ = ::open(tmp_.data(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd_ < 0) return Fail("create", errno, false);
  open_ = true;
  return true;
}

bool AtomicFileStream::Write(const void* data, size_t size) {
  if (fd_ < 0) return Fail("write", EBADF, true);
  const auto* bytes = static_cast<const char*>(data);
  size_t done = 0;
  while (done < size) {
    const ssize_t n = ::write(fd_, bytes + done, size - done);
    if (n < 0) {
      if (errno == EINTR) continue;
      return Fail("write", errno, true);
    }
    done += static_cast<size_t>(n);
  }
  bytes_ += static_cast<int64_t>(size);
  return true;
}

bool AtomicFileStream::Commit() {
  if (fd_ < 0) return Fail("sync", EBADF, true);
  if (::fsync(fd_) != 0) return Fail("sync", errno, true);
  const int fd = fd_;
  fd_ = -1;
  if (::close(fd) != 0) return Fail("close", errno, true);
  if (std::rename(tmp_.data(), path_.c_str()) != 0) return Fail("rename", errno, true);
  open_ = false;
  if (const char* step = SyncDirectory(dir_.c_str())) return Fail(step, errno, false);
  return true;
}

std::string AtomicFileStream::ErrorMessage(const std::string& what) const {
  if (step_ == nullptr) return "";
  const std::string step = step_;
  const std::string file = step == "rename"                      ? "to " + path_
                           : step.find("directory") != step.npos ? dir_
                                                                 : std::string(tmp_.data());
  const std::string named = step == "rename" ? "rename " + file : step + " " + file;
  return "cannot write " + what + " " + path_ + ": " + named + ": " + std::strerror(error_);
}

void WriteFileAtomically(const std::string& path, std::string_view bytes, const std::string& what) {
  AtomicFileStream out(path);
  if (!out.Open() || !out.Write(bytes.data(), bytes.size()) || !out.Commit()) {
    throw std::runtime_error(out.ErrorMessage(what));
  }
}

int RemoveStaleTemporaries(const std::string& dir, std::string_view prefix) {
  namespace fs = std::filesystem;
  constexpr std::string_view kInfix = ".tmp.";
  const std::string own = std::to_string(::getpid());
  int removed = 0;
  std::error_code error;
  for (const fs::directory_entry& entry : fs::directory_iterator(dir, error)) {
    const std::string name = entry.path().filename().string();
    const size_t infix = name.rfind(kInfix);
    if (infix == std::string::npos || name.compare(0, prefix.size(), prefix) != 0) continue;
    const std::string_view pid = std::string_view(name).substr(infix + kInfix.size());
    if (pid.empty() || pid.find_first_not_of("0123456789") != std::string_view::npos ||
        pid == own) {
      continue;
    }
    std::error_code ignored;
    if (entry.is_regular_file(ignored) && fs::remove(entry.path(), ignored)) ++removed;
  }
  return removed;
}

void RenameIntoPlace(const std::string& tmp, const std::string& path, const std::string& what) {
  const auto fail = [&](const std::string& step, int err) {
    throw std::runtime_error("cannot write " + what + " " + path + ": " + step + ": " +
                             std::strerror(err));
  };
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    const int err = errno;
    ::unlink(tmp.c_str());
    fail("rename to " + path, err);
  }
  const std::string dir = DirectoryOf(path);
  if (const char* step = SyncDirectory(dir.c_str())) fail(std::string(step) + " " + dir, errno);
}

}  // namespace rl
