#include "launch/proc.h"

#include <fcntl.h>
#include <poll.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <csignal>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "common/host_ports.h"
#include "common/text_format.h"

namespace rl::launch {

uint64_t ProcessStartTime(pid_t pid) {
  if (pid <= 0) return 0;
  std::ifstream in("/proc/" + std::to_string(pid) + "/stat");
  std::string stat;
  if (!std::getline(in, stat)) return 0;
  // "PID (COMM) STATE PPID ...": COMM may hold spaces and parentheses, so count fields after the
  // last ')'. STATE is field 3, the start time field 22.
  const size_t close = stat.rfind(')');
  if (close == std::string::npos) return 0;
  std::istringstream fields(stat.substr(close + 1));
  std::string field;
  for (int i = 3; i <= 22; ++i) {
    if (!(fields >> field)) return 0;
    if (i == 3 && (field == "Z" || field == "X")) return 0;
  }
  try {
    return std::stoull(field);
  } catch (const std::exception&) {
    return 0;
  }
}

bool SameProcessAlive(pid_t pid, uint64_t start_time) {
  return start_time != 0 && ProcessStartTime(pid) == start_time;
}

std::string SignalName(int signal) {
  const char* abbrev = sigabbrev_np(signal);
  return abbrev != nullptr ? std::string("SIG") + abbrev : "SIG" + std::to_string(signal);
}

std::string DescribeWaitStatus(int wait_status) {
  if (WIFSIGNALED(wait_status)) {
    const int sig = WTERMSIG(wait_status);
    return "signal " + std::to_string(sig) + " (" + SignalName(sig) + ")";
  }
  return "status " + std::to_string(WEXITSTATUS(wait_status));
}

int ShellExitCode(int wait_status) {
  return WIFSIGNALED(wait_status) ? 128 + WTERMSIG(wait_status) : WEXITSTATUS(wait_status);
}

bool HoldsFileOpen(pid_t pid, const std::string& path) {
  std::error_code ec;
  const std::filesystem::path fds = "/proc/" + std::to_string(pid) + "/fd";
  for (const auto& entry : std::filesystem::directory_iterator(fds, ec)) {
    std::error_code link_ec;
    if (std::filesystem::read_symlink(entry.path(), link_ec) == path) return true;
  }
  return false;
}

bool ListensOnTcp(int port) { return SocketsOnPort("tcp", port, "0A") > 0; }  // 0A: LISTEN

std::string ExecutableDir() {
  std::error_code ec;
  const std::filesystem::path exe = std::filesystem::read_symlink("/proc/self/exe", ec);
  if (ec) throw std::runtime_error("cannot read /proc/self/exe: " + ec.message());
  return exe.parent_path().string();
}

std::string RunAndCapture(const std::vector<std::string>& argv) {
  int out[2], err[2];
  if (pipe2(out, O_CLOEXEC) != 0) throw std::runtime_error("pipe: " + std::string(strerror(errno)));
  if (pipe2(err, O_CLOEXEC) != 0) {
    close(out[0]);
    close(out[1]);
    throw std::runtime_error("pipe: " + std::string(strerror(errno)));
  }
  std::vector<char*> args;
  for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  const pid_t pid = fork();
  if (pid == 0) {
    dup2(out[1], STDOUT_FILENO);
    dup2(err[1], STDERR_FILENO);
    execv(args[0], args.data());
    const std::string why = "cannot run: " + std::string(strerror(errno)) + "\n";
    (void)!write(STDERR_FILENO, why.data(), why.size());
    _exit(127);
  }
  close(out[1]);
  close(err[1]);
  if (pid < 0) {
    close(out[0]);
    close(err[0]);
    throw std::runtime_error("fork: " + std::string(strerror(errno)));
  }
  std::string text[2];
  pollfd fds[2] = {{out[0], POLLIN, 0}, {err[0], POLLIN, 0}};
  int open_fds = 2;
  while (open_fds > 0) {
    if (poll(fds, 2, -1) < 0 && errno != EINTR) break;
    for (int i = 0; i < 2; ++i) {
      if (fds[i].fd < 0 || fds[i].revents == 0) continue;
      char buf[4096];
      const ssize_t n = read(fds[i].fd, buf, sizeof(buf));
      if (n > 0) {
        text[i].append(buf, static_cast<size_t>(n));
      } else if (n == 0 || errno != EINTR) {
        close(fds[i].fd);
        fds[i].fd = -1;
        --open_fds;
      }
    }
  }
  int status = 0;
  while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
    std::string last = text[1];
    while (!last.empty() && last.back() == '\n') last.pop_back();
    last = last.substr(last.rfind('\n') == std::string::npos ? 0 : last.rfind('\n') + 1);
    throw std::runtime_error(argv[0] + " failed (" + DescribeWaitStatus(status) + ")" +
                             (last.empty() ? "" : ": " + last));
  }
  return text[0];
}

FolderFiles LookInFolder(const std::string& dir,
                         const std::function<bool(const std::string& name)>& match) {
  namespace fs = std::filesystem;
  FolderFiles found;
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(dir, ec)) {
    const std::string name = entry.path().filename().string();
    if (!match(name)) continue;
    std::error_code size_ec;
    const auto size = static_cast<int64_t>(entry.file_size(size_ec));
    if (size_ec) continue;
    ++found.files;
    found.bytes += size;
    if (size > found.largest_bytes) {
      found.largest_bytes = size;
      found.largest = name;
    }
  }
  return found;
}

namespace {

FolderFiles TemporaryFiles(const std::string& dir) {
  return LookInFolder(
      dir, [](const std::string& name) { return name.find(".tmp.") != std::string::npos; });
}

}  // namespace

StopWrites::StopWrites(std::string dir, double began, const RestartLimits& limits)
    : dir_(std::move(dir)),
      deadline_(began + limits.stop_seconds),
      stall_(limits.stop_stall_seconds),
      end_(began + limits.stop_write_limit) {
  if (!dir_.empty()) seen_ = TemporaryFiles(dir_);
}

bool StopWrites::Writing(double now) {
  if (dir_.empty() || now >= end_) return false;
  if (now - looked_ >= 0.25) {
    looked_ = now;
    const FolderFiles seen = TemporaryFiles(dir_);
    if (seen.files != seen_.files || seen.bytes != seen_.bytes) changed_ = now;
    seen_ = seen;
  }
  return changed_ >= 0 && now - changed_ < stall_;
}

std::string StopWrites::Describe() const {
  if (seen_.files == 0) return "";
  return " (" + seen_.largest + ": " +
         FormatDouble("%.0f", static_cast<double>(seen_.largest_bytes) / 1e6) + " MB so far)";
}

}  // namespace rl::launch
