// Clocks: wall time for message headers, a monotonic clock for rates and timeouts.
#pragma once

#include <chrono>
#include <cstdint>

namespace rl {

// Microseconds since the Unix epoch.
inline int64_t WallMicros() {
  return std::chrono::duration_cast<std::chrono::microseconds>(
             std::chrono::system_clock::now().time_since_epoch())
      .count();
}

// Seconds on a monotonic clock (arbitrary origin).
inline double MonoSeconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

// Nanoseconds on the same monotonic clock, for timing short calls.
inline int64_t MonoNanos() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

// The rate of a growing count over the interval between two readings: the stats of every
// process (steps/s, updates/s, inserts/s). Not thread-safe.
class RateMeter {
 public:
  // (count - count at the previous call) / (now - time of the previous call), in events per
  // second; 0 on the first call and when no time has passed.
  double Take(int64_t count, double now) {
    const double dt = now - last_time_;
    const double rate =
        (last_time_ >= 0 && dt > 0) ? static_cast<double>(count - last_count_) / dt : 0.0;
    last_time_ = now;
    last_count_ = count;
    return rate;
  }

 private:
  int64_t last_count_ = 0;
  double last_time_ = -1.0;
};

}  // namespace rl
