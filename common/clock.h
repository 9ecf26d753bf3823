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

// Counts events and reports their rate over the interval since the last call of Rate().
class RateMeter {
 public:
  void Add(int64_t n = 1) { count_ += n; }
  // Events per second since the previous call (0 on the first call).
  double Rate() {
    const double now = MonoSeconds();
    const double dt = now - last_time_;
    const double rate =
        (last_time_ > 0 && dt > 0) ? static_cast<double>(count_ - last_count_) / dt : 0.0;
    last_time_ = now;
    last_count_ = count_;
    return rate;
  }
  int64_t count() const { return count_; }

 private:
  int64_t count_ = 0;
  int64_t last_count_ = 0;
  double last_time_ = 0;
};

}  // namespace rl
