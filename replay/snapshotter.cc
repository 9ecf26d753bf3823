#include "replay/snapshotter.h"

#include <fcntl.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <stdexcept>
#include <utility>

#include "common/atomic_file.h"
#include "common/clock.h"

namespace rl::replay {

namespace {

// What the child reports through its pipe before it exits.
struct ChildReport {
  int32_t ok;
  int32_t error;  // errno of the failed step
  char step[24];  // the failed step (AtomicFileStream::failed_step), NUL-terminated
  int64_t bytes;
  double seconds;  // open, write, fsync and rename
};

// Monotonic seconds from clock_gettime (async-signal-safe, for the child).
double ChildSeconds() {
  timespec t{};
  ::clock_gettime(CLOCK_MONOTONIC, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

// The child's whole life: system calls only (see the file comment of snapshotter.h).
[[noreturn]] void RunChild(pid_t parent, int report_fd, const StateStream& stream,
                           AtomicFileStream* file) {
  // Die with the parent; if it is already gone, write nothing.
  ::prctl(PR_SET_PDEATHSIG, SIGKILL);
  if (::getppid() != parent) ::_exit(3);
  ::setpriority(PRIO_PROCESS, 0, ::getpriority(PRIO_PROCESS, 0) + 10);
  const double start = ChildSeconds();
  const bool ok = file->Open() && stream.Write(file) && file->Commit();
  ChildReport report{};
  report.ok = ok ? 1 : 0;
  report.error = file->error();
  if (const char* step = file->failed_step()) {
    for (size_t k = 0; k + 1 < sizeof(report.step) && step[k] != '\0'; ++k)
      report.step[k] = step[k];
  }
  report.bytes = file->bytes_written();
  report.seconds = ChildSeconds() - start;
  ssize_t n = 0;
  do {
    n = ::write(report_fd, &report, sizeof(report));
  } while (n < 0 && errno == EINTR);
  ::_exit(ok ? 0 : 1);
}

std::string Megabytes(int64_t bytes) {
  char buf[32];
  if (bytes < 1000000) {
    std::snprintf(buf, sizeof(buf), "%.1f kB", static_cast<double>(bytes) / 1e3);
  } else {
    std::snprintf(buf, sizeof(buf), "%.1f MB", static_cast<double>(bytes) / 1e6);
  }
  return buf;
}

}  // namespace

void SnapshotterOptions::Validate() const {
  if (!std::isfinite(every_seconds) || every_seconds <= 0) {
    throw std::invalid_argument("snapshots: every_seconds must be finite and > 0, got " +
                                std::to_string(every_seconds));
  }
}

Snapshotter::Snapshotter(SnapshotterOptions options, std::string kind,
                         std::function<std::string(StateStream*)> fill,
                         std::function<int64_t()> version)
    : options_(std::move(options)),
      kind_(std::move(kind)),
      fill_(std::move(fill)),
      version_(std::move(version)) {
  options_.Validate();
  RemoveStaleTemporaries();
  // The state as it starts (empty, or just loaded) needs no snapshot.
  written_version_ = version_();
}

Snapshotter::~Snapshotter() { Wait(); }

void Snapshotter::RemoveStaleTemporaries() const {
  if (options_.path.empty()) return;
  // Writers die with their process, leaving their temporary file: PATH.tmp.<pid>.
  const std::filesystem::path path(options_.path);
  rl::RemoveStaleTemporaries(path.has_parent_path() ? path.parent_path().string() : ".",
                             path.filename().string() + ".tmp.");
}

bool Snapshotter::Tick(double now) {
  if (child_ > 0) {
    int status = 0;
    const pid_t done = ::waitpid(child_, &status, WNOHANG);
    if (done == child_) Reaped(status);
  }
  if (next_ < 0) next_ = now + options_.every_seconds;
  if (options_.path.empty() || child_ > 0 || now < next_) return false;
  next_ = now + options_.every_seconds;
  if (version_() == written_version_) return false;
  return StartNow();
}

bool Snapshotter::StartNow() {
  if (options_.path.empty() || child_ > 0) return false;
  // Build the section list (referring to the state) and the file's names, then fork.
  const double start = MonoSeconds();
  stream_ = std::make_unique<StateStream>(kind_);
  summary_ = fill_(stream_.get());
  child_version_ = version_();
  file_ = std::make_unique<AtomicFileStream>(options_.path);
  int fds[2] = {-1, -1};
  if (::pipe2(fds, O_CLOEXEC | O_NONBLOCK) != 0) {
    ++stats_.failed;
    std::fprintf(stderr, "%s: snapshot not started: pipe: %s\n", options_.program.c_str(),
                 std::strerror(errno));
    return false;
  }
  const pid_t parent = ::getpid();
  const double before_fork = MonoSeconds();
  const pid_t pid = ::fork();
  const double after_fork = MonoSeconds();
  if (pid == 0) {
    ::close(fds[0]);
    RunChild(parent, fds[1], *stream_, file_.get());
  }
  ::close(fds[1]);
  if (pid < 0) {
    ::close(fds[0]);
    ++stats_.failed;
    std::fprintf(stderr, "%s: snapshot not started: fork: %s\n", options_.program.c_str(),
                 std::strerror(errno));
    return false;
  }
  child_ = pid;
  pipe_ = fds[0];
  started_ = start;
  stats_.last_fork_seconds = after_fork - before_fork;
  stats_.last_pause_seconds = after_fork - start;
  stats_.max_pause_seconds = std::max(stats_.max_pause_seconds, stats_.last_pause_seconds);
  return true;
}

void Snapshotter::Reaped(int status) {
  ChildReport r{};
  const bool reported = ::read(pipe_, &r, sizeof(r)) == static_cast<ssize_t>(sizeof(r));
  ::close(pipe_);
  pipe_ = -1;
  const pid_t pid = child_;
  child_ = -1;
  if (reported && r.ok == 1 && WIFEXITED(status) && WEXITSTATUS(status) == 0) {
    ++stats_.written;
    stats_.last_bytes = r.bytes;
    stats_.last_write_seconds = r.seconds;
    written_version_ = child_version_;
    std::printf(
        "%s: snapshot %lld written to %s (%s): %s, pause %.2f ms (fork %.2f ms), write %.2f s\n",
        options_.program.c_str(), static_cast<long long>(stats_.written), options_.path.c_str(),
        summary_.c_str(), Megabytes(r.bytes).c_str(), 1e3 * stats_.last_pause_seconds,
        1e3 * stats_.last_fork_seconds, r.seconds);
    std::fflush(stdout);
  } else {
    ++stats_.failed;
    std::string why;
    if (reported && r.ok == 0 && r.step[0] != '\0') {
      why = "cannot write snapshot " + options_.path + ": " + r.step + " " + options_.path +
            ".tmp." + std::to_string(pid) + ": " + std::strerror(r.error);
    } else if (WIFSIGNALED(status)) {
      why = "its writer was killed by signal " + std::to_string(WTERMSIG(status));
    } else {
      why = "its writer exited with status " + std::to_string(WEXITSTATUS(status));
    }
    std::fprintf(stderr, "%s: snapshot failed (the previous one is kept): %s\n",
                 options_.program.c_str(), why.c_str());
  }
  stream_.reset();
  file_.reset();
}

void Snapshotter::Wait() {
  if (child_ <= 0) return;
  int status = 0;
  pid_t done = -1;
  do {
    done = ::waitpid(child_, &status, 0);
  } while (done < 0 && errno == EINTR);
  if (done == child_) {
    Reaped(status);
  } else {
    child_ = -1;
    ::close(pipe_);
    pipe_ = -1;
  }
}

bool Snapshotter::Finish() {
  Wait();
  if (options_.path.empty() || version_() == written_version_) return true;
  const double start = MonoSeconds();
  StateStream stream(kind_);
  const std::string summary = fill_(&stream);
  AtomicFileStream file(options_.path);
  if (!file.Open() || !stream.Write(&file) || !file.Commit()) {
    ++stats_.failed;
    std::fprintf(stderr, "%s: last snapshot failed (the previous one is kept): %s\n",
                 options_.program.c_str(), file.ErrorMessage("snapshot").c_str());
    return false;
  }
  ++stats_.written;
  written_version_ = version_();
  std::printf("%s: last snapshot written to %s (%s): %s in %.2f s\n", options_.program.c_str(),
              options_.path.c_str(), summary.c_str(), Megabytes(file.bytes_written()).c_str(),
              MonoSeconds() - start);
  std::fflush(stdout);
  return true;
}

}  // namespace rl::replay
