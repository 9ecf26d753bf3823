#include "evaluator/announced_checkpoint.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <stdexcept>
#include <string_view>
#include <system_error>

namespace rl::evaluator {
namespace {

// `text` fit for a log line: control characters replaced, at most 200 characters.
std::string Printable(std::string_view text) {
  std::string out(text.substr(0, 200));
  for (char& c : out) {
    if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) c = '?';
  }
  if (text.size() > 200) out += "...";
  return out;
}

// Closes a file descriptor when it goes out of scope.
struct Fd {
  int fd = -1;
  ~Fd() {
    if (fd >= 0) ::close(fd);
  }
};

// The whole file open at fd (a regular file of at most max_bytes), or why not.
std::string ReadBounded(int fd, int64_t max_bytes, std::string* why) {
  struct stat st {};
  if (::fstat(fd, &st) != 0) {
    *why = std::string("cannot stat it: ") + std::strerror(errno);
    return {};
  }
  if (!S_ISREG(st.st_mode)) {
    *why = "not a regular file";
    return {};
  }
  if (st.st_size > max_bytes) {
    *why = std::to_string(st.st_size) + " bytes, above the bound of " + std::to_string(max_bytes);
    return {};
  }
  std::string bytes(static_cast<size_t>(st.st_size), '\0');
  size_t have = 0;
  while (true) {
    // A file that grew since fstat is read up to the bound and one byte more.
    if (have == bytes.size()) {
      if (static_cast<int64_t>(have) > max_bytes) {
        *why = "it grew above the bound of " + std::to_string(max_bytes) + " bytes";
        return {};
      }
      bytes.resize(have + std::min<size_t>(1 << 16, static_cast<size_t>(max_bytes) + 1 - have));
    }
    const ssize_t got = ::read(fd, bytes.data() + have, bytes.size() - have);
    if (got < 0 && errno == EINTR) continue;
    if (got < 0) {
      *why = std::string("cannot read it: ") + std::strerror(errno);
      return {};
    }
    if (got == 0) break;
    have += static_cast<size_t>(got);
  }
  bytes.resize(have);
  return bytes;
}

}  // namespace

nn::Checkpoint ReadAnnouncedCheckpoint(const std::string& announced, const std::string& folder,
                                       int64_t max_bytes) {
  namespace fs = std::filesystem;
  const auto refuse = [&announced](const std::string& why) {
    return std::runtime_error("announced checkpoint '" + Printable(announced) +
                              "' refused: " + why);
  };
  if (announced.empty() || announced.size() > 4096 || announced.find('\0') != std::string::npos) {
    throw refuse("not a path");
  }
  const fs::path path(announced);
  const std::string name = path.filename().string();
  if (name.empty() || name == "." || name == "..") throw refuse("it names no file");
  // The folder the path leads to must be the checkpoint folder itself.
  if (folder.empty()) throw refuse("no checkpoint folder to read it from (no run folder)");
  std::error_code ec;
  const fs::path dir = fs::canonical(folder, ec);
  if (ec) throw refuse("the checkpoint folder " + folder + " cannot be resolved: " + ec.message());
  const fs::path parent = path.has_parent_path() ? path.parent_path() : fs::path(".");
  const fs::path where = fs::canonical(parent, ec);
  if (ec || where != dir) throw refuse("not a file of the run's checkpoint folder " + dir.string());
  // Opened from the folder itself, without following a symbolic link and without blocking (a
  // FIFO or a device opens at once and is refused as no regular file).
  Fd dir_fd{::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC)};
  if (dir_fd.fd < 0) {
    throw refuse("cannot open the checkpoint folder: " + std::string(std::strerror(errno)));
  }
  Fd file{
      ::openat(dir_fd.fd, name.c_str(), O_RDONLY | O_NONBLOCK | O_NOFOLLOW | O_NOCTTY | O_CLOEXEC)};
  if (file.fd < 0) {
    throw refuse(errno == ELOOP ? "a symbolic link"
                                : "cannot open it: " + std::string(std::strerror(errno)));
  }
  std::string why;
  const std::string bytes = ReadBounded(file.fd, max_bytes, &why);
  if (!why.empty()) throw refuse(why);
  return nn::ParseCheckpoint(bytes, Printable(announced));
}

}  // namespace rl::evaluator
