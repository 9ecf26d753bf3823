// Helpers of the benchmarks: repeated measurements and one JSON object per line.
#pragma once

#include <time.h>  // NOLINT(modernize-deprecated-headers): POSIX clock_gettime, not in <ctime>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <limits>
#include <string>
#include <utility>
#include <vector>

namespace rl::bench {

struct Summary {
  double min = 0, median = 0, max = 0;
};

inline Summary Summarize(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  Summary s;
  if (v.empty()) return s;
  s.min = v.front();
  s.max = v.back();
  const size_t n = v.size();
  s.median = n % 2 == 1 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
  return s;
}

// Whether rates are per second of the process's CPU time (RL_BENCH_CLOCK=cpu) instead of wall
// time: on a machine shared with other jobs, the time the benchmark actually ran. Only for
// measurements on one thread (a second thread's time would count twice).
inline bool CpuClock() {
  const char* clock = std::getenv("RL_BENCH_CLOCK");
  return clock != nullptr && std::strcmp(clock, "cpu") == 0;
}

// Seconds on the clock of Rate(): wall time, or the process's CPU time (see CpuClock()).
inline double ClockSeconds() {
  if (CpuClock()) {
    timespec ts{};
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
  }
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

// Runs `chunk` (which performs `ops_per_chunk` operations) repeatedly for at least min_seconds
// after `warmup` chunks; returns operations per second (see ClockSeconds()).
inline double Rate(const std::function<void()>& chunk, double ops_per_chunk, double min_seconds,
                   int warmup = 1) {
  for (int i = 0; i < warmup; ++i) chunk();
  const double start = ClockSeconds();
  double ops = 0;
  double elapsed = 0;
  do {
    chunk();
    ops += ops_per_chunk;
    elapsed = ClockSeconds() - start;
  } while (elapsed < min_seconds);
  return ops / elapsed;
}

// Repeats a rate measurement and summarises it.
inline Summary Repeat(int repeats, const std::function<double()>& measure) {
  std::vector<double> v;
  for (int i = 0; i < repeats; ++i) v.push_back(measure());
  return Summarize(v);
}

// Prints {"bench": name, "value": median, "unit": unit, "min":..., "median":..., "max":...,
// "repeats": n, <extra>} on one line. `extra` is a JSON fragment like "\"batch\": 32" or "".
inline void Emit(const std::string& name, const std::string& unit, const Summary& s, int repeats,
                 const std::string& extra = "") {
  std::printf(
      "{\"bench\": \"%s\", \"value\": %.6g, \"unit\": \"%s\", \"min\": %.6g, \"median\": %.6g, "
      "\"max\": %.6g, \"repeats\": %d%s%s%s}\n",
      name.c_str(), s.median, unit.c_str(), s.min, s.median, s.max, repeats,
      extra.empty() ? "" : ", ", extra.c_str(), CpuClock() ? ", \"clock\": \"process_cpu\"" : "");
  std::fflush(stdout);
}

// The positional arguments of a benchmark, named by its usage line ("bench_x [REPEATS] ...").
// -h or --help anywhere prints the usage and exits 0. More arguments than the usage names, or one
// read as a number that is not a positive number, print an error and the usage and exit 2.
// Arguments are counted from `first` (1, or 2 after a mode such as bench_replay's --mac).
class Args {
 public:
  Args(int argc, char** argv, std::string usage, int max_count, int first = 1)
      : usage_(std::move(usage)) {
    for (int i = 1; i < argc; ++i) {
      if (std::strcmp(argv[i], "-h") == 0 || std::strcmp(argv[i], "--help") == 0) {
        std::printf("%s\n", usage_.c_str());
        std::exit(0);
      }
    }
    for (int i = first; i < argc; ++i) args_.emplace_back(argv[i]);
    if (static_cast<int>(args_.size()) > max_count) Fail("too many arguments");
  }

  // The i-th argument (from 0) as a positive number, `fallback` when it is not given.
  double Number(size_t i, double fallback) const {
    if (i >= args_.size()) return fallback;
    char* end = nullptr;
    const double v = std::strtod(args_[i].c_str(), &end);
    if (end == args_[i].c_str() || *end != '\0' || !(v > 0)) {
      Fail("'" + args_[i] + "' is not a positive number");
    }
    return v;
  }
  int Int(size_t i, int fallback) const {
    const double v = Number(i, fallback);
    if (v > std::numeric_limits<int>::max() || v != std::floor(v)) {
      Fail("'" + args_[i] + "' is not a whole number of at most " +
           std::to_string(std::numeric_limits<int>::max()));
    }
    return static_cast<int>(v);
  }
  // The i-th argument as given, `fallback` when it is not given.
  std::string Text(size_t i, const std::string& fallback) const {
    return i < args_.size() ? args_[i] : fallback;
  }

  [[noreturn]] void Fail(const std::string& why) const {
    std::fprintf(stderr, "error: %s\n%s\n", why.c_str(), usage_.c_str());
    std::exit(2);
  }

 private:
  std::string usage_;
  std::vector<std::string> args_;
};

// The arguments of most benchmarks: REPEATS (5) and SECONDS per repeat (1), read through Args
// with a usage line naming `program` and saying `what` it measures.
struct Timing {
  int repeats;
  double seconds;
};
inline Timing ReadTiming(int argc, char** argv, const std::string& program,
                         const std::string& what) {
  const Args args(argc, argv,
                  "usage: " + program + " [REPEATS (5)] [SECONDS per repeat (1)]\n" + what, 2);
  return {args.Int(0, 5), args.Number(1, 1.0)};
}

}  // namespace rl::bench
