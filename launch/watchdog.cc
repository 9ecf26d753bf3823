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
  std::string writes_at_stop;
};

void Say(const std::string& line) { (void)!write(STDERR_FILENO, line.data(), line.size()); }

// The watchdog process: reads "PID START ROLE [FOLDER]" lines until the launcher's end of the pipe
// closes, then gives the processes limits.stop_seconds to stop (more to one still writing its last
// files in FOLDER) and SIGKILLs those still running.
[[noreturn]] void WatchdogMain(int fd, const RestartLimits& limits) {
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
      if (!(line >> w.pid >> w.start >> w.role)) continue;
      line.get();  // the space before the folder
      std::getline(line, w.writes_at_stop);
      watched.push_back(w);
    }
  }
  // The launcher is gone (or done): wait for the processes, then kill the ones left.
  const double start = MonoSeconds();
  std::vector<StopWrites> stops;
  stops.reserve(watched.size());
  for (const Watched& w : watched) stops.emplace_back(w.writes_at_stop, start, limits);
  for (;;) {
    const double now = MonoSeconds();
    bool alive = false;
    for (size_t i = 0; i < watched.size(); ++i) {
      Watched& w = watched[i];
      if (w.pid == 0) continue;
      if (!SameProcessAlive(w.pid, w.start)) {
        w.pid = 0;
        continue;
      }
      alive = true;
      if (!stops[i].Overdue(now)) continue;
      kill(w.pid, SIGKILL);
      Say("launch: the launcher is gone; killed " + w.role + " (pid " + std::to_string(w.pid) +
          "), still running " + FormatDouble("%.0f", now - start) + " s after\n");
      w.pid = 0;
    }
    if (!alive) _exit(0);
    poll(nullptr, 0, 100);
  }
}

}  // namespace

Watchdog::Watchdog(const RestartLimits& limits) {
  int fds[2];
  if (pipe2(fds, O_CLOEXEC) != 0) {
    throw std::runtime_error("cannot make the watchdog's pipe: " + std::string(strerror(errno)));
  }
  const pid_t child = fork();
  if (child == 0) {
    close(fds[1]);
    if (fork() == 0) WatchdogMain(fds[0], limits);
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

void Watchdog::Watch(pid_t pid, const std::string& role, const std::string& writes_at_stop) {
  const std::string line = std::to_string(pid) + " " + std::to_string(ProcessStartTime(pid)) + " " +
                           role + " " + writes_at_stop + "\n";
  (void)!write(fd_, line.data(), line.size());
}

}  // namespace rl::launch
