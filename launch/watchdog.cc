#include "launch/watchdog.h"

#include <fcntl.h>
#include <poll.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <csignal>
#include <cstdint>
#include <cstring>
#include <sstream>
#include <stdexcept>
#include <vector>

#include "common/clock.h"
#include "common/text_format.h"
#include "launch/proc.h"

namespace rl::launch {
namespace {

struct Watched {
  pid_t pid = 0;
  uint64_t start = 0;
  std::string role;
};

void Say(const std::string& line) { (void)!write(STDERR_FILENO, line.data(), line.size()); }

// The watchdog process: reads "PID START ROLE" lines until the launcher's end of the pipe closes,
// then gives the processes `grace` seconds to stop and SIGKILLs those still running.
[[noreturn]] void WatchdogMain(int fd, double grace) {
  prctl(PR_SET_NAME, "launch-watchdog");
  for (int sig : {SIGINT, SIGTERM, SIGHUP, SIGQUIT, SIGPIPE}) signal(sig, SIG_IGN);
  sigset_t none;
  sigemptyset(&none);
  sigprocmask(SIG_SETMASK, &none, nullptr);
  // No file of the launcher's (its run folder's lock above all) but the pipe and stderr.
  const int null = open("/dev/null", O_RDWR);
  if (null >= 0) {
    dup2(null, STDIN_FILENO);
    dup2(null, STDOUT_FILENO);
  }
  if (dup2(fd, 3) != 3) _exit(1);
  if (close_range(4, ~0U, 0) != 0) {
    for (int i = 4; i < 1024; ++i) close(i);
  }
  std::vector<Watched> watched;
  std::string pending;
  char buf[4096];
  for (;;) {
    const ssize_t n = read(3, buf, sizeof(buf));
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) break;
    pending.append(buf, static_cast<size_t>(n));
    for (size_t eol; (eol = pending.find('\n')) != std::string::npos;) {
      std::istringstream line(pending.substr(0, eol));
      pending.erase(0, eol + 1);
      Watched w;
      if (line >> w.pid >> w.start >> w.role) watched.push_back(w);
    }
  }
  // The launcher is gone (or done): wait for the processes, then kill the ones left.
  const double deadline = MonoSeconds() + grace;
  for (;;) {
    std::vector<const Watched*> alive;
    for (const Watched& w : watched) {
      if (SameProcessAlive(w.pid, w.start)) alive.push_back(&w);
    }
    if (alive.empty()) _exit(0);
    if (MonoSeconds() >= deadline) {
      for (const Watched* w : alive) {
        kill(w->pid, SIGKILL);
        Say("launch: the launcher is gone; killed " + w->role + " (pid " + std::to_string(w->pid) +
            "), still running " + FormatDouble("%g", grace) + " s after\n");
      }
      _exit(0);
    }
    poll(nullptr, 0, 100);
  }
}

}  // namespace

Watchdog::Watchdog(double grace_seconds) {
  int fds[2];
  if (pipe2(fds, O_CLOEXEC) != 0) {
    throw std::runtime_error("cannot make the watchdog's pipe: " + std::string(strerror(errno)));
  }
  const pid_t child = fork();
  if (child == 0) {
    close(fds[1]);
    if (fork() == 0) WatchdogMain(fds[0], grace_seconds);
    _exit(0);
  }
  close(fds[0]);
  if (child < 0) {
    close(fds[1]);
    throw std::runtime_error("cannot fork the watchdog: " + std::string(strerror(errno)));
  }
  while (waitpid(child, nullptr, 0) < 0 && errno == EINTR) {
  }
  fd_ = fds[1];
}

Watchdog::~Watchdog() {
  if (fd_ >= 0) close(fd_);
}

void Watchdog::Watch(pid_t pid, const std::string& role) {
  const std::string line =
      std::to_string(pid) + " " + std::to_string(ProcessStartTime(pid)) + " " + role + "\n";
  (void)!write(fd_, line.data(), line.size());
}

}  // namespace rl::launch
