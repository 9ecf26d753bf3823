#include "common/atomic_file.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <stdexcept>

namespace rl {
namespace {

[[noreturn]] void Fail(const std::string& what, const std::string& path, const std::string& tmp,
                       const std::string& step, int err) {
  if (!tmp.empty()) ::unlink(tmp.c_str());
  throw std::runtime_error("cannot write " + what + " " + path + ": " + step + ": " +
                           std::strerror(err));
}

std::string DirectoryOf(const std::string& path) {
  const size_t slash = path.rfind('/');
  if (slash == std::string::npos) return ".";
  if (slash == 0) return "/";
  return path.substr(0, slash);
}

}  // namespace

std::string TemporaryPathFor(const std::string& path) {
  return path + ".tmp." + std::to_string(::getpid());
}

void WriteFileAtomically(const std::string& path, std::string_view bytes, const std::string& what) {
  const std::string tmp = TemporaryPathFor(path);
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) Fail(what, path, "", "create " + tmp, errno);
  size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
    if (n < 0) {
      if (errno == EINTR) continue;
      const int err = errno;
      ::close(fd);
      Fail(what, path, tmp, "write " + tmp, err);
    }
    done += static_cast<size_t>(n);
  }
  if (::fsync(fd) != 0) {
    const int err = errno;
    ::close(fd);
    Fail(what, path, tmp, "sync " + tmp, err);
  }
  if (::close(fd) != 0) Fail(what, path, tmp, "close " + tmp, errno);
  RenameIntoPlace(tmp, path, what);
}

void RenameIntoPlace(const std::string& tmp, const std::string& path, const std::string& what) {
  if (std::rename(tmp.c_str(), path.c_str()) != 0)
    Fail(what, path, tmp, "rename to " + path, errno);
  // Persist the rename. Some file systems cannot fsync a directory (EINVAL); the data is in
  // place by then, so only real I/O errors are reported.
  const std::string dir = DirectoryOf(path);
  const int dir_fd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (dir_fd < 0) Fail(what, path, "", "open directory " + dir, errno);
  if (::fsync(dir_fd) != 0 && errno != EINVAL) {
    const int err = errno;
    ::close(dir_fd);
    Fail(what, path, "", "sync directory " + dir, err);
  }
  ::close(dir_fd);
}

}  // namespace rl
