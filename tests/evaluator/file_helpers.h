// Helpers of the evaluator's tests: counting a text's occurrences in another, and unblocking a
// FIFO that code under test might (wrongly) open blocking.
#pragma once

#include <fcntl.h>
#include <unistd.h>

#include <atomic>
#include <string>
#include <thread>

namespace rl::evaluator::testing {

// How many times `needle` stands in `text`, occurrences not overlapping.
inline int CountOccurrences(const std::string& text, const std::string& needle) {
  int n = 0;
  for (size_t pos = text.find(needle); pos != std::string::npos;
       pos = text.find(needle, pos + needle.size())) {
    ++n;
  }
  return n;
}

// While it lives, opens the FIFO at `path` for writing as soon as someone opens it for reading,
// and closes it: code that (wrongly) blocks opening the FIFO returns instead of hanging the test.
class FifoUnblocker {
 public:
  explicit FifoUnblocker(const std::string& path)
      : thread_([this, path] {
          while (!done_) {
            const int fd = ::open(path.c_str(), O_WRONLY | O_NONBLOCK);
            if (fd >= 0) {
              ::close(fd);
              return;
            }
            std::this_thread::yield();
          }
        }) {}
  FifoUnblocker(const FifoUnblocker&) = delete;
  FifoUnblocker& operator=(const FifoUnblocker&) = delete;
  ~FifoUnblocker() {
    done_ = true;
    thread_.join();
  }

 private:
  std::atomic<bool> done_{false};
  std::thread thread_;
};

}  // namespace rl::evaluator::testing
