// Temporary directories for tests: TempDir, an empty directory removed with its contents when it
// goes, and TempDirTest, a fixture that gives each test one.
#pragma once

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <system_error>

#include <gtest/gtest.h>

namespace rl {

/// An empty directory of its own, made by mkdtemp under gtest's temporary directory
/// (::testing::TempDir(): $TEST_TMPDIR, else /tmp) and removed with its contents by the
/// destructor, which ignores errors. The constructor throws std::runtime_error, naming the pattern
/// and the system's reason, if mkdtemp fails: a test that makes one then fails with that message.
/// Not copyable.
class TempDir {
 public:
  TempDir() {
    const std::string pattern =
        (std::filesystem::path(::testing::TempDir()) / "rl_test_XXXXXX").string();
    std::string name = pattern;
    if (::mkdtemp(name.data()) == nullptr) {
      const int error = errno;
      throw std::runtime_error("cannot make a temporary directory " + pattern + ": " +
                               std::strerror(error));
    }
    path_ = name;
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  ~TempDir() {
    std::error_code ignored;
    std::filesystem::remove_all(path_, ignored);
  }

  /// The directory.
  const std::filesystem::path& path() const { return path_; }
  /// The path of `name` (relative, may hold slashes) inside the directory; nothing is made.
  std::filesystem::path operator/(const std::filesystem::path& name) const { return path_ / name; }

 private:
  std::filesystem::path path_;
};

/// A fixture that gives each test an empty directory, `dir_`, made when the fixture is constructed
/// (derived fixtures may use it in their member initializers) and removed with its contents after
/// the test.
class TempDirTest : public ::testing::Test {
 protected:
  TempDir temp_dir_;
  const std::filesystem::path dir_ = temp_dir_.path();
};

}  // namespace rl
