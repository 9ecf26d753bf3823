#include "launch/supervisor.h"

#include <fcntl.h>
#include <poll.h>
#include <sys/prctl.h>
#include <sys/signalfd.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <csignal>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <optional>
#include <stdexcept>

#include "common/clock.h"
#include "common/text_format.h"
#include "launch/proc.h"
#include "launch/run_folder.h"
#include "launch/watchdog.h"

namespace rl::launch {
namespace {

// Writes all of `text` to `fd`, ignoring errors: the launcher's output may be a terminal that has
// gone, and it must go on stopping its run.
void Say(int fd, const std::string& text) {
  size_t done = 0;
  while (done < text.size()) {
    const ssize_t n = write(fd, text.data() + done, text.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return;
    done += static_cast<size_t>(n);
  }
}

void AppendToFile(const std::string& path, const std::string& text) {
  const int fd = open(path.c_str(), O_WRONLY | O_CREAT | O_APPEND | O_CLOEXEC, 0644);
  if (fd < 0) return;
  Say(fd, text);
  close(fd);
}

int OpenOrThrow(const std::string& path, int flags) {
  const int fd = open(path.c_str(), flags | O_CLOEXEC, 0644);
  if (fd < 0) throw std::runtime_error("cannot open " + path + ": " + strerror(errno));
  return fd;
}

// The last `count` lines of `path` written after `offset` (at most its last 64 KB).
std::vector<std::string> LastLines(const std::string& path, off_t offset, size_t count) {
  const int fd = open(path.c_str(), O_RDONLY | O_CLOEXEC);
  std::vector<std::string> lines;
  if (fd < 0) return lines;
  struct stat st {};
  fstat(fd, &st);
  const off_t from = std::max(offset, st.st_size - static_cast<off_t>(65536));
  std::string text(static_cast<size_t>(std::max<off_t>(0, st.st_size - from)), '\0');
  const ssize_t n = pread(fd, text.data(), text.size(), from);
  close(fd);
  text.resize(n > 0 ? static_cast<size_t>(n) : 0);
  size_t begin = 0;
  while (begin < text.size()) {
    size_t end = text.find('\n', begin);
    if (end == std::string::npos) end = text.size();
    if (end > begin) lines.push_back(text.substr(begin, end - begin));
    begin = end + 1;
  }
  if (lines.size() > count) lines.erase(lines.begin(), lines.end() - static_cast<long>(count));
  return lines;
}

// The bytes of the files beside `file` whose names start with its stem (a recording's
// main.lcmlog.0, .1, ...).
int64_t RecordedBytes(const std::string& file) {
  const std::filesystem::path path(file);
  const std::string stem = path.stem().string();
  return LookInFolder(path.parent_path().string(),
                      [&stem](const std::string& name) { return name.rfind(stem, 0) == 0; })
      .bytes;
}

// How a process ended, as a sentence's verb: "exited with status 3", "was killed by signal 9
// (SIGKILL)".
std::string HowItEnded(int wait_status) {
  return WIFSIGNALED(wait_status) ? "was killed by " + DescribeWaitStatus(wait_status)
                                  : "exited with " + DescribeWaitStatus(wait_status);
}

std::string Seconds(double s) { return FormatDouble(s < 10 ? "%.1f" : "%.0f", s) + " s"; }

// Forks and executes `command` with its output on `out_fd`, in this process group, SIGHUP ignored
// and `stop_signal` as its parent-death signal. Returns the pid.
pid_t Spawn(const std::vector<std::string>& command, int out_fd, int stop_signal) {
  std::vector<char*> argv;
  for (const std::string& a : command) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  const int null = open("/dev/null", O_RDONLY | O_CLOEXEC);
  const pid_t parent = getpid();
  const pid_t pid = fork();
  if (pid == 0) {
    sigset_t none;
    sigemptyset(&none);
    sigprocmask(SIG_SETMASK, &none, nullptr);
    signal(SIGHUP, SIG_IGN);
    signal(SIGPIPE, SIG_DFL);
    // The launcher may have died between fork() and prctl(): then the signal would never come.
    if (prctl(PR_SET_PDEATHSIG, stop_signal) != 0 || getppid() != parent) _exit(126);
    if (null >= 0) dup2(null, STDIN_FILENO);
    dup2(out_fd, STDOUT_FILENO);
    dup2(out_fd, STDERR_FILENO);
    execvp(argv[0], argv.data());
    const std::string why =
        std::string("launch: cannot run ") + argv[0] + ": " + strerror(errno) + "\n";
    Say(STDERR_FILENO, why);
    _exit(127);
  }
  const int fork_errno = errno;
  if (null >= 0) close(null);
  if (pid < 0) throw std::runtime_error("cannot fork: " + std::string(strerror(fork_errno)));
  return pid;
}

}  // namespace

struct Supervisor::Proc {
  explicit Proc(const PlannedProcess* p, const RestartLimits& limits) : plan(p), policy(limits) {}
  const PlannedProcess* plan;
  RestartPolicy policy;
  pid_t pid = 0;         // 0: not running
  double started = 0;    // MonoSeconds() of its start
  off_t log_offset = 0;  // where this start's output begins in its log
  off_t scanned = 0;     // readiness: the log read up to here
  std::string partial;   // readiness: an incomplete last line
  bool ready = false;
  double restart_at = -1;  // a restart is due at this time (< 0: none)
  bool down = false;       // not to be started again
  bool termed = false;     // stopping: SIGTERM sent
  bool killed = false;     // stopping: SIGKILL sent
  // Stopping: when it may be killed (its writes_at_stop folder watched), and when the launcher
  // last said that it waits for its writes.
  std::optional<StopWrites> stop;
  double told_at = -1e9;

  void StopBegan(double began, const RestartLimits& limits) {
    stop.emplace(plan->writes_at_stop, began, limits);
  }
};

int ExitStatusOf(RunEnd end) {
  switch (end) {
    case RunEnd::kGoalReached:
      return 0;
    case RunEnd::kNotReached:
    case RunEnd::kProcessDown:
      return 1;
    case RunEnd::kFailed:
      return 2;
    case RunEnd::kHangUp:
      return 129;
    case RunEnd::kInterrupted:
      return 130;
  }
  return 1;
}

int BlockRunSignals() {
  sigset_t set;
  sigemptyset(&set);
  sigaddset(&set, SIGCHLD);
  sigaddset(&set, SIGTERM);
  // A signal the launcher was started ignoring stays ignored: SIGINT in a job a shell started in
  // the background, SIGHUP under nohup.
  for (int sig : {SIGINT, SIGHUP}) {
    struct sigaction old {};
    sigaction(sig, nullptr, &old);
    if (old.sa_handler != SIG_IGN) sigaddset(&set, sig);
  }
  if (sigprocmask(SIG_BLOCK, &set, nullptr) != 0) {
    throw std::runtime_error("cannot block signals: " + std::string(strerror(errno)));
  }
  const int fd = signalfd(-1, &set, SFD_NONBLOCK | SFD_CLOEXEC);
  if (fd < 0) throw std::runtime_error("cannot make a signalfd: " + std::string(strerror(errno)));
  return fd;
}

Supervisor::Supervisor(const RunPlan& plan, const Placement& placement, int signal_fd,
                       Watchdog* watchdog)
    : plan_(plan), placement_(placement), signal_fd_(signal_fd), watchdog_(watchdog) {
  procs_.reserve(plan.processes.size());
  for (const PlannedProcess& p : plan.processes) procs_.emplace_back(&p, plan.settings.limits);
}

Supervisor::~Supervisor() {
  // The path of an exception in the launcher: the same rule as an orderly stop, every process
  // at once.
  const double began = MonoSeconds();
  for (Proc& p : procs_) {
    if (p.pid <= 0) continue;
    kill(p.pid, placement_.StopSignal(*p.plan));
    p.StopBegan(began, plan_.settings.limits);
  }
  while (AnyRunning(true) || AnyRunning(false)) {
    int status = 0;
    const pid_t pid = waitpid(-1, &status, WNOHANG);
    for (Proc& p : procs_) {
      if (pid > 0 && p.pid == pid) p.pid = 0;
    }
    if (pid < 0 && errno == ECHILD) break;
    if (pid > 0) continue;
    const double now = MonoSeconds();
    for (Proc& p : procs_) {
      if (p.pid <= 0 || p.killed || !p.stop->Overdue(now)) continue;
      kill(p.pid, SIGKILL);
      p.killed = true;
    }
    poll(nullptr, 0, 50);
  }
  if (shown_fd_ >= 0) close(shown_fd_);
  if (shown_log_fd_ >= 0) close(shown_log_fd_);
}

void Supervisor::Tell(Proc* p, const std::string& line) {
  Say(STDERR_FILENO, line + "\n");
  if (!p->plan->shown) AppendToFile(p->plan->log, line + "\n");
}

void Supervisor::Start(Proc* p) {
  const PlannedProcess& planned = *p->plan;
  int out_fd = -1;
  if (planned.shown) {
    // Its output comes to the launcher, which shows it and writes its log.
    int fds[2];
    if (pipe2(fds, O_CLOEXEC) != 0) {
      throw std::runtime_error("cannot make a pipe: " + std::string(strerror(errno)));
    }
    if (shown_fd_ >= 0) close(shown_fd_);
    shown_fd_ = fds[0];
    fcntl(shown_fd_, F_SETFL, O_NONBLOCK);
    out_fd = fds[1];
    if (shown_log_fd_ >= 0) close(shown_log_fd_);
    shown_log_fd_ = OpenOrThrow(planned.log, O_WRONLY | O_CREAT | O_TRUNC);
  } else {
    out_fd = OpenOrThrow(planned.log, O_WRONLY | O_CREAT | O_APPEND);
    p->log_offset = lseek(out_fd, 0, SEEK_END);
  }
  pid_t pid = 0;
  try {
    pid = Spawn(placement_.Command(planned), out_fd, placement_.StopSignal(planned));
  } catch (...) {
    close(out_fd);
    throw;
  }
  close(out_fd);
  p->pid = pid;
  p->started = MonoSeconds();
  p->scanned = p->log_offset;
  p->partial.clear();
  p->ready = planned.ready.kind == Readiness::kAtStart;
  p->restart_at = -1;
  AppendToFile(plan_.identity.run_dir + "/pids", planned.role + " " + std::to_string(pid) + "\n");
  if (watchdog_ != nullptr) watchdog_->Watch(pid, planned.role, planned.writes_at_stop);
}

void Supervisor::Fail(Proc* p, const std::string& why) {
  const std::vector<std::string> lines = LastLines(p->plan->log, p->log_offset, 5);
  std::string text = "launch: " + p->plan->role + " " + why +
                     (lines.empty() ? "; its log says nothing" : "; its log says:") + "\n";
  for (const std::string& line : lines) text += line + "\n";
  Say(STDERR_FILENO, text);
  BeginStop(RunEnd::kFailed);
}

void Supervisor::OnExit(Proc* p, int wait_status) {
  const double ran = MonoSeconds() - p->started;
  p->pid = 0;
  if (phase_ != Phase::kRunning) return;
  const PlannedProcess& planned = *p->plan;
  const std::string& role = planned.role;
  if (planned.ends_run) {
    const int code = ShellExitCode(wait_status);
    BeginStop(code == 0     ? RunEnd::kGoalReached
              : code == 130 ? RunEnd::kInterrupted
                            : RunEnd::kNotReached);
    return;
  }
  // Its job ending (scancel, a requeue): Slurm stops every process; so does the launcher.
  if (const std::string ending = placement_.Ending(); !ending.empty()) {
    Tell(p, "launch: " + role + " " + HowItEnded(wait_status) + ": " + ending);
    BeginStop(RunEnd::kInterrupted);
    return;
  }
  // A process whose node has left the job cannot be started again; the run goes on without it.
  if (!planned.essential) {
    if (const std::string lost = placement_.Lost(planned); !lost.empty()) {
      p->down = true;
      AppendToFile(plan_.identity.run_dir + "/restarts",
                   IsoNow() + " " + role + " status " + std::to_string(ShellExitCode(wait_status)) +
                       " lost 0\n");
      Tell(p, "launch: " + role + " " + HowItEnded(wait_status) + ": " + lost +
                  "; the run goes on without it");
      return;
    }
  }
  const ExitDecision d =
      planned.restart ? p->policy.OnExit(ran, wait_status, p->ready) : ExitDecision{};
  switch (d.verdict) {
    case ExitVerdict::kStartupFailure:
      Fail(p, "failed at its start (" + DescribeWaitStatus(wait_status) + ", " + Seconds(ran) +
                  " after it started)");
      return;
    case ExitVerdict::kRestart:
      AppendToFile(plan_.identity.run_dir + "/restarts",
                   IsoNow() + " " + role + " status " + std::to_string(ShellExitCode(wait_status)) +
                       " restart " + std::to_string(d.restart) + "\n");
      Tell(p, "launch: " + role + " " + HowItEnded(wait_status) + " after " + Seconds(ran) +
                  "; restarting it in " + FormatDouble("%g", d.delay) + " s (restart " +
                  std::to_string(d.restart) + " of " +
                  std::to_string(plan_.settings.limits.max_restarts) + ")");
      p->ready = false;
      p->restart_at = MonoSeconds() + d.delay;
      return;
    case ExitVerdict::kFinished:
    case ExitVerdict::kSpent: {
      p->down = true;
      const std::string what =
          d.verdict == ExitVerdict::kSpent
              ? HowItEnded(wait_status) + "; its " +
                    std::to_string(plan_.settings.limits.max_restarts) + " restarts are spent"
              : HowItEnded(wait_status) + " while the run goes on; it is not restarted";
      Tell(p, "launch: " + role + " " + what +
                  (planned.essential ? ": stopping the run" : "; the run goes on without it"));
      if (planned.essential) BeginStop(RunEnd::kProcessDown);
      return;
    }
  }
}

void Supervisor::Reap() {
  for (;;) {
    int status = 0;
    const pid_t pid = waitpid(-1, &status, WNOHANG);
    if (pid <= 0) return;
    for (Proc& p : procs_) {
      if (p.pid == pid) {
        OnExit(&p, status);
        break;
      }
    }
  }
}

void Supervisor::CheckReadiness(Proc* p, double now) {
  if (p->pid == 0 || p->ready) return;
  const Readiness& r = p->plan->ready;
  if (r.kind == Readiness::kOpensFile) {
    p->ready = HoldsFileOpen(p->pid, r.text);
  } else if (r.kind == Readiness::kListens) {
    p->ready = ListensOnTcp(std::atoi(r.text.c_str()));
  } else if (r.kind == Readiness::kLogLine) {
    // The lines this start wrote, from where it began: never an earlier start's.
    const int fd = open(p->plan->log.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd >= 0) {
      char buf[8192];
      ssize_t n;
      while (!p->ready && (n = pread(fd, buf, sizeof(buf), p->scanned)) > 0) {
        p->scanned += n;
        p->partial.append(buf, static_cast<size_t>(n));
        for (size_t eol; !p->ready && (eol = p->partial.find('\n')) != std::string::npos;) {
          p->ready = p->partial.compare(0, r.text.size(), r.text) == 0;
          p->partial.erase(0, eol + 1);
        }
      }
      close(fd);
    }
  }
  if (!p->ready && now - p->started > plan_.settings.limits.ready_timeout) {
    Fail(p, "was not ready " + Seconds(plan_.settings.limits.ready_timeout) +
                " after its start (log: " + p->plan->log + ")");
  }
}

void Supervisor::StartNextInOrder() {
  while (phase_ == Phase::kRunning && next_ < procs_.size()) {
    if (next_ > 0 && !procs_[next_ - 1].ready && !procs_[next_ - 1].down) return;
    Proc& p = procs_[next_];
    if (p.plan->ends_run && on_all_ready_) on_all_ready_();
    ++next_;
    Start(&p);
  }
}

void Supervisor::BeginStop(RunEnd end) {
  if (phase_ != Phase::kRunning) return;
  end_ = end;
  phase_ = Phase::kStopping;
  if (end == RunEnd::kInterrupted) Say(STDOUT_FILENO, "\nlaunch: interrupted, stopping the run\n");
  if (end == RunEnd::kHangUp) {
    Say(STDERR_FILENO, "launch: hang-up (its terminal closed?), stopping the run\n");
  }
  stop_began_ = MonoSeconds();
  stop_deadline_ = stop_began_ + plan_.settings.limits.stop_seconds;
  for (Proc& p : procs_) {
    p.restart_at = -1;
    if (p.pid > 0 && !p.plan->stops_last) {
      kill(p.pid, placement_.StopSignal(*p.plan));
      p.termed = true;
      p.StopBegan(stop_began_, plan_.settings.limits);
    }
  }
}

bool Supervisor::AnyRunning(bool last) const {
  for (const Proc& p : procs_) {
    if (p.pid > 0 && p.plan->stops_last == last) return true;
  }
  return false;
}

void Supervisor::AdvanceStop(double now) {
  if (phase_ == Phase::kStopping) {
    if (AnyRunning(false)) {
      for (Proc& p : procs_) {
        if (p.pid <= 0 || p.plan->stops_last || p.killed) continue;
        if (!p.stop->Overdue(now)) {
          // Not overdue past the usual seconds: still writing its last files. Said every 10 s.
          if (now >= stop_deadline_ && now - p.told_at >= 10) {
            p.told_at = now;
            Tell(&p, "launch: " + p.plan->role + " is still writing" + p.stop->Describe() +
                         "; waiting for it");
          }
          continue;
        }
        Tell(&p, "launch: " + p.plan->role + " did not stop; killing it");
        kill(p.pid, SIGKILL);
        p.killed = true;
      }
      return;
    }
    // Every other process has stopped; the recorder goes once it has written what they sent:
    // with nothing published any more, when its files stop growing (it flushes every 100 ms),
    // within 3 s.
    phase_ = Phase::kStoppingLast;
    stop_deadline_ = now + 3;
    last_check_ = 0;
  }
  // The recorder first, then what carries the traffic it records (a TCP hub).
  bool recording = false;
  for (const Proc& p : procs_) {
    recording |= p.pid > 0 && p.plan->stops_last && p.plan->ready.kind == Readiness::kOpensFile;
  }
  for (Proc& p : procs_) {
    if (p.pid == 0 || !p.plan->stops_last) continue;
    if (!p.termed && p.plan->ready.kind != Readiness::kOpensFile) {
      if (recording) continue;
      kill(p.pid, placement_.StopSignal(*p.plan));
      p.termed = true;
      stop_deadline_ = std::max(stop_deadline_, now + 5);
    } else if (!p.termed) {
      if (now - last_check_ < 0.1) continue;
      last_check_ = now;
      const int64_t bytes = RecordedBytes(p.plan->ready.text);
      steady_checks_ = bytes == recorded_bytes_ ? steady_checks_ + 1 : 0;
      recorded_bytes_ = bytes;
      if (steady_checks_ < 2 && now < stop_deadline_) continue;
      kill(p.pid, placement_.StopSignal(*p.plan));  // it closes its file; the rest is lost
      p.termed = true;
      stop_deadline_ = now + 5;
    } else if (!p.killed && now >= stop_deadline_) {
      Tell(&p, "launch: " + p.plan->role + " did not stop; killing it");
      kill(p.pid, SIGKILL);
      p.killed = true;
    }
  }
  if (!AnyRunning(true) && shown_fd_ < 0) phase_ = Phase::kDone;
}

void Supervisor::ForwardShownOutput() {
  char buf[8192];
  for (;;) {
    const ssize_t n = read(shown_fd_, buf, sizeof(buf));
    if (n > 0) {
      Say(STDOUT_FILENO, std::string(buf, static_cast<size_t>(n)));
      Say(shown_log_fd_, std::string(buf, static_cast<size_t>(n)));
      continue;
    }
    if (n < 0 && errno == EINTR) continue;
    if (n < 0 && errno == EAGAIN) return;
    close(shown_fd_);  // end of file: the shown process and all that shared its pipe are gone
    shown_fd_ = -1;
    return;
  }
}

void Supervisor::HandleSignals() {
  bool child = false, interrupt = false, hangup = false;
  signalfd_siginfo si{};
  while (read(signal_fd_, &si, sizeof(si)) == static_cast<ssize_t>(sizeof(si))) {
    child |= si.ssi_signo == SIGCHLD;
    interrupt |= si.ssi_signo == SIGINT || si.ssi_signo == SIGTERM;
    hangup |= si.ssi_signo == SIGHUP;
  }
  // A stop first: the processes that Ctrl-C reached too then exit into a stopping run.
  if (interrupt) BeginStop(RunEnd::kInterrupted);
  if (hangup) BeginStop(RunEnd::kHangUp);
  if (child) Reap();
}

double Supervisor::NextWakeup(double now) const {
  if (phase_ != Phase::kRunning) return 0.05;
  double wake = 1;
  for (const Proc& p : procs_) {
    if (p.pid > 0 && !p.ready) wake = std::min(wake, 0.05);
    if (p.restart_at >= 0) wake = std::min(wake, std::max(0.0, p.restart_at - now));
  }
  return wake;
}

RunEnd Supervisor::Run() {
  StartNextInOrder();
  while (phase_ != Phase::kDone) {
    const double now = MonoSeconds();
    pollfd fds[2] = {{signal_fd_, POLLIN, 0}, {shown_fd_, POLLIN, 0}};
    const int wait_ms = static_cast<int>(NextWakeup(now) * 1000) + 1;
    if (poll(fds, shown_fd_ >= 0 ? 2 : 1, wait_ms) < 0 && errno != EINTR) {
      throw std::runtime_error("poll: " + std::string(strerror(errno)));
    }
    if (fds[0].revents != 0) HandleSignals();
    if (shown_fd_ >= 0 && fds[1].revents != 0) ForwardShownOutput();
    const double after = MonoSeconds();
    if (phase_ == Phase::kRunning) {
      for (Proc& p : procs_) {
        CheckReadiness(&p, after);
        if (phase_ == Phase::kRunning && p.restart_at >= 0 && after >= p.restart_at) Start(&p);
      }
      StartNextInOrder();
    }
    if (phase_ != Phase::kRunning) AdvanceStop(after);
  }
  return end_;
}

}  // namespace rl::launch
