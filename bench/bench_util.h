// Helpers of the benchmarks: repeated measurements and one JSON object per line.
#pragma once

#include <time.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <string>
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

}  // namespace rl::bench
