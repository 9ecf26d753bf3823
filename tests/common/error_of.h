// ErrorOf: the message of the exception a piece of test code throws, for tests that check what
// an error says.
#pragma once

#include <exception>
#include <string>

namespace rl {

/// Calls f() and returns the what() of the std::exception it throws, or "" if it throws none.
template <class F>
std::string ErrorOf(F f) {
  try {
    f();
  } catch (const std::exception& e) {
    return e.what();
  }
  return "";
}

}  // namespace rl
