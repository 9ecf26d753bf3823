// Checks for our own invariants. RL_CHECK aborts with a message when a condition that the code
// guarantees does not hold (a bug, never bad input: bad input throws std::runtime_error or
// std::invalid_argument with a message saying what was expected).
#pragma once

#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <string>

namespace rl::internal {

// Collects the streamed context of a failed check and aborts when destroyed.
class CheckFailure {
 public:
  CheckFailure(const char* file, int line, const char* cond) {
    stream_ << file << ":" << line << ": check failed: " << cond << " ";
  }
  CheckFailure(const CheckFailure&) = delete;
  CheckFailure& operator=(const CheckFailure&) = delete;
  [[noreturn]] ~CheckFailure() {
    std::fprintf(stderr, "%s\n", stream_.str().c_str());
    std::fflush(stderr);
    std::abort();
  }
  std::ostream& stream() { return stream_; }

 private:
  std::ostringstream stream_;
};

}  // namespace rl::internal

#define RL_CHECK(cond) \
  if (cond) {          \
  } else               \
    ::rl::internal::CheckFailure(__FILE__, __LINE__, #cond).stream()

#ifdef NDEBUG
#define RL_DCHECK(cond) \
  if (true) {           \
  } else                \
    ::rl::internal::CheckFailure(__FILE__, __LINE__, #cond).stream()
#else
#define RL_DCHECK(cond) RL_CHECK(cond)
#endif
