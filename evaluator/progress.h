// What the evaluator's long pieces of work (scoring, the second metric, t-SNE maps) share with the
// service that runs them: progress lines, and a tick after every step that keeps the service's
// stats flowing and ends the work when a stop is requested.
#pragma once

#include <cstdarg>
#include <cstdio>
#include <functional>
#include <string>

namespace rl::evaluator {

/// Thrown by a Tick when a stop was requested: the work in progress is dropped.
struct Interrupted {};

/// Called after every env step (and between iterations) of long work: publishes the service's
/// stats when due, and throws Interrupted when a stop was requested. May be empty (no ticks).
/// After every step, not every episode: an evaluator at a low priority on a busy machine can take
/// longer than the monitor's silence limit over one episode, and would be taken for a dead one.
using Tick = std::function<void()>;

/// printf-style progress lines to a stream, flushed at once; a null stream drops them.
class ProgressLog {
 public:
  explicit ProgressLog(std::FILE* out) : out_(out) {}
  void operator()(const char* fmt, ...) const __attribute__((format(printf, 2, 3))) {
    if (out_ == nullptr) return;
    va_list args;
    va_start(args, fmt);
    std::vfprintf(out_, fmt, args);
    va_end(args);
    std::fflush(out_);
  }

 private:
  std::FILE* out_;
};

/// Writes "evaluator: <line>" to stderr: work that failed without stopping the service.
inline void LogError(const std::string& line) {
  std::fprintf(stderr, "evaluator: %s\n", line.c_str());
  std::fflush(stderr);
}

}  // namespace rl::evaluator
