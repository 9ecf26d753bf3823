// A test fixture with an empty directory of its own.
#pragma once

#include <cstdlib>
#include <filesystem>
#include <string>

#include <gtest/gtest.h>

namespace rl {

/// Gives each test an empty directory, `dir_`, made by mkdtemp under gtest's temporary directory,
/// and removes it with its contents after the test. A fixture that overrides SetUp calls
/// TempDirTest::SetUp first.
class TempDirTest : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string pattern = ::testing::TempDir() + "rl_test_XXXXXX";
    ASSERT_NE(::mkdtemp(pattern.data()), nullptr) << pattern;
    dir_ = pattern;
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }

  std::filesystem::path dir_;
};

}  // namespace rl
