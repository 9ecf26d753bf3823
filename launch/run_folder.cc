#include "launch/run_folder.h"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/random.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "common/text_format.h"
#include "launch/launch_options.h"
#include "launch/proc.h"

namespace rl::launch {
namespace {

namespace fs = std::filesystem;

std::string ErrnoText() { return std::strerror(errno); }

// A number's shortest text that reads back the same (600, 2.5).
std::string Number(double v) { return FormatDouble("%.15g", v); }

}  // namespace

int RunHeader::Port() const {
  // udpm://GROUP:PORT?options
  const size_t scheme = lcm_url.find("://");
  const size_t colon = lcm_url.find(':', scheme == std::string::npos ? 0 : scheme + 3);
  if (scheme == std::string::npos || colon == std::string::npos) return 0;
  return std::atoi(lcm_url.c_str() + colon + 1);
}

std::string FormatRunHeader(const RunHeader& h) {
  std::string s = "# Run of preset '" + h.preset + "', started " + h.started + "\n";
  s += "# run-id = " + std::to_string(h.run_id) + "\n";
  s += "# lcm-url = " + h.lcm_url + "\n";
  s += "# lcm-bulk-url = " + h.lcm_bulk_url + "\n";
  s += "# lcm-samples-url = " + h.lcm_samples_url + "\n";
  s += "# actors = " + std::to_string(h.actors) + " (of " + std::to_string(h.num_actors) +
       "), seed = " + std::to_string(h.seed) + ", goal = " + h.goal +
       ", time budget = " + Number(h.time_budget) + " s\n";
  if (!h.extra.empty()) s += "# extra: " + h.extra + "\n";
  return s;
}

RunHeader ParseRunHeader(const std::string& config_text, const std::string& path) {
  RunHeader h;
  bool have_preset = false, have_id = false, have_actors = false;
  std::istringstream in(config_text);
  // The rest of `line` after `prefix`, when it starts with it.
  const auto after = [](const std::string& line, const char* prefix) -> std::optional<std::string> {
    const size_t n = std::strlen(prefix);
    if (line.compare(0, n, prefix) != 0) return std::nullopt;
    return line.substr(n);
  };
  for (std::string line; std::getline(in, line);) {
    while (!line.empty() && (line.back() == ' ' || line.back() == '\r')) line.pop_back();
    if (line.empty() || line[0] != '#') continue;
    if (const auto rest = after(line, "# Run of preset '"); rest && !have_preset) {
      const size_t end = rest->rfind("', started ");
      if (end == std::string::npos) continue;
      h.preset = rest->substr(0, end);
      h.started = rest->substr(end + 11);
      have_preset = true;
    } else if (const auto id = after(line, "# run-id = "); id && !have_id) {
      char* end = nullptr;
      h.run_id = std::strtoll(id->c_str(), &end, 10);
      have_id = !id->empty() && *end == '\0';
    } else if (const auto url = after(line, "# lcm-url = "); url && h.lcm_url.empty()) {
      h.lcm_url = *url;
    } else if (const auto bulk = after(line, "# lcm-bulk-url = "); bulk && h.lcm_bulk_url.empty()) {
      h.lcm_bulk_url = *bulk;
    } else if (const auto samples = after(line, "# lcm-samples-url = ");
               samples && h.lcm_samples_url.empty()) {
      h.lcm_samples_url = *samples;
    } else if (after(line, "# actors = ") && !have_actors) {
      // "# actors = 4 (of 4), seed = 1, goal = 475, time budget = 600 s"
      unsigned long long seed = 0;
      char goal[64] = {};
      have_actors = std::sscanf(line.c_str(),
                                "# actors = %d (of %d), seed = %llu, goal = %63[^,], time budget "
                                "= %lf s",
                                &h.actors, &h.num_actors, &seed, goal, &h.time_budget) == 5;
      h.seed = seed;
      h.goal = goal;
    } else if (const auto extra = after(line, "# extra: "); extra && h.extra.empty()) {
      h.extra = *extra;
    }
  }
  if (!have_preset || !have_id || !have_actors) {
    throw LaunchError(path + " lacks the launcher's header (preset, run id, actors and seed)");
  }
  return h;
}

std::string LocalTimeNow(const char* format) {
  const std::time_t now = std::time(nullptr);
  std::tm tm{};
  localtime_r(&now, &tm);
  char buf[64];
  std::strftime(buf, sizeof(buf), format, &tm);
  return buf;
}

std::string IsoNow() {
  std::string s = LocalTimeNow("%Y-%m-%dT%H:%M:%S%z");
  if (s.size() < 5) return s;
  return s.substr(0, s.size() - 2) + ":" + s.substr(s.size() - 2);  // +0100 -> +01:00
}

std::string CreateRunFolder(const std::string& path, bool suffix_when_taken) {
  std::error_code ec;
  const fs::path wanted = fs::absolute(path, ec).lexically_normal();
  if (ec) throw LaunchError("cannot create the run folder " + path + ": " + ec.message());
  const std::string base = wanted.has_filename() ? wanted.string() : wanted.parent_path().string();
  fs::create_directories(fs::path(base).parent_path(), ec);
  if (ec) throw LaunchError("cannot create the run folder " + base + ": " + ec.message());
  for (int k = 1; k <= 1000; ++k) {
    std::string candidate = k == 1 ? base : base + "-" + std::to_string(k);
    if (mkdir(candidate.c_str(), 0777) == 0) return candidate;
    if (errno != EEXIST) {
      throw LaunchError("cannot create the run folder " + candidate + ": " + ErrnoText());
    }
    if (suffix_when_taken) continue;
    if (!fs::is_directory(candidate, ec)) {
      throw LaunchError("cannot create the run folder " + candidate +
                        ": it exists and is no folder");
    }
    if (fs::is_empty(candidate, ec) && !ec) return candidate;
    throw LaunchError("the run folder " + candidate +
                      " exists and is not empty (pick another --out, or continue its run with "
                      "--resume " +
                      candidate + ")");
  }
  throw LaunchError("cannot create the run folder " + base + ": 1000 folders of that name exist");
}

RunLock::RunLock(const std::string& run_dir) {
  const std::string path = run_dir + "/lock";
  fd_ = open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
  if (fd_ < 0) throw LaunchError("cannot create the lock file " + path + ": " + ErrnoText());
  if (flock(fd_, LOCK_EX | LOCK_NB) != 0) {
    const int err = errno;
    close(fd_);
    fd_ = -1;
    if (err != EWOULDBLOCK) throw LaunchError("cannot lock " + path + ": " + std::strerror(err));
    const std::optional<pid_t> pid = RunningLauncher(run_dir);
    throw LaunchError("the run in " + run_dir + " is going (" +
                      (pid ? "launcher pid " + std::to_string(*pid) : "another launcher") +
                      "): stop it with scripts/launch.sh --stop " + run_dir + " first");
  }
}

RunLock::~RunLock() {
  if (fd_ >= 0) close(fd_);
}

void WriteLaunchPid(const std::string& run_dir) {
  const pid_t pid = getpid();
  std::ofstream out(run_dir + "/launch.pid", std::ios::trunc);
  out << pid << " " << ProcessStartTime(pid) << "\n";
  if (!out.flush()) throw LaunchError("cannot write " + run_dir + "/launch.pid");
}

std::optional<pid_t> RunningLauncher(const std::string& run_dir) {
  std::ifstream in(run_dir + "/launch.pid");
  long long pid = 0;
  uint64_t start = 0;
  if (!(in >> pid >> start) || pid <= 0) return std::nullopt;
  if (!SameProcessAlive(static_cast<pid_t>(pid), start)) return std::nullopt;
  return static_cast<pid_t>(pid);
}

void EnsureKeyFile(const std::string& path) {
  std::error_code ec;
  if (fs::is_regular_file(path, ec) && fs::file_size(path, ec) > 0 && !ec) return;
  unsigned char key[32];
  size_t got = 0;
  while (got < sizeof(key)) {
    const ssize_t n = getrandom(key + got, sizeof(key) - got, 0);
    if (n < 0 && errno != EINTR) throw LaunchError("cannot make the run's key: " + ErrnoText());
    if (n > 0) got += static_cast<size_t>(n);
  }
  const std::string tmp = path + ".tmp";
  const int fd = open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0600);
  bool ok = fd >= 0 && fchmod(fd, 0600) == 0 &&
            write(fd, key, sizeof(key)) == static_cast<ssize_t>(sizeof(key)) && fsync(fd) == 0;
  const std::string why = ErrnoText();
  if (fd >= 0) ok = close(fd) == 0 && ok;
  if (!ok || rename(tmp.c_str(), path.c_str()) != 0) {
    unlink(tmp.c_str());
    throw LaunchError("cannot write the run's key file " + path + ": " + (ok ? ErrnoText() : why));
  }
}

int64_t RandomRunId() {
  uint64_t v = 0;
  unsigned char bytes[6];
  if (getrandom(bytes, sizeof(bytes), 0) != static_cast<ssize_t>(sizeof(bytes))) {
    throw LaunchError("cannot draw a run id: " + ErrnoText());
  }
  for (unsigned char b : bytes) v = (v << 8) | b;
  return static_cast<int64_t>(v) + 1;
}

}  // namespace rl::launch
