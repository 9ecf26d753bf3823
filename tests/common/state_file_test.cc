#include "common/state_file.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace rl {
namespace {

namespace fs = std::filesystem;

StateFile Sample() {
  StateFile s("learner td3");
  const std::vector<float> floats = {1.5f, -2.0f, 3.25f};
  s.PutFloats("net", floats);
  s.PutInt("updates", 42);
  s.PutText("net.arch", "linear(3,1)");
  return s;
}

// The message of the exception `f` throws (empty if it throws none).
template <class F>
std::string ErrorOf(F f) {
  try {
    f();
  } catch (const std::exception& e) {
    return e.what();
  }
  return "";
}

TEST(StateFileTest, RoundTripsEverySectionThroughAFile) {
  const fs::path path = fs::temp_directory_path() / ("state_file_test_" + std::to_string(getpid()));
  Sample().Save(path.string());
  const StateFile s = StateFile::Load(path.string(), "learner td3");
  fs::remove(path);
  EXPECT_EQ(std::vector<float>(s.Floats("net").begin(), s.Floats("net").end()),
            (std::vector<float>{1.5f, -2.0f, 3.25f}));
  EXPECT_EQ(s.Int("updates"), 42);
  EXPECT_EQ(s.Text("net.arch"), "linear(3,1)");
  EXPECT_TRUE(s.Has("net"));
  EXPECT_FALSE(s.Has("other"));
}

TEST(StateFileTest, RefusesTornCorruptedAndForeignFiles) {
  const std::string bytes = Sample().Serialize();
  EXPECT_NO_THROW(StateFile::Parse(bytes, "learner td3"));
  // Torn: every proper prefix is refused.
  for (size_t n = 0; n < bytes.size(); n += 7) {
    EXPECT_THROW(StateFile::Parse(bytes.substr(0, n), "learner td3"), std::runtime_error) << n;
  }
  // A flipped bit anywhere fails the checksum.
  for (size_t k = 0; k < bytes.size(); k += 5) {
    std::string flipped = bytes;
    flipped[k] = static_cast<char>(flipped[k] ^ 0x10);
    EXPECT_THROW(StateFile::Parse(flipped, "learner td3"), std::runtime_error) << k;
  }
  EXPECT_NE(ErrorOf([&] { StateFile::Parse(bytes, "learner dqn"); }).find("'learner td3'"),
            std::string::npos);
  EXPECT_NE(ErrorOf([&] { StateFile::Parse("not a state", "learner td3"); }).find("magic"),
            std::string::npos);
  EXPECT_NE(ErrorOf([] { StateFile::Load("/nonexistent/state.bin", "x"); }).find("cannot read"),
            std::string::npos);
}

TEST(StateFileTest, NamesMissingAndMistypedSections) {
  const StateFile s = Sample();
  EXPECT_NE(ErrorOf([&] { s.Floats("missing"); }).find("'missing'"), std::string::npos);
  EXPECT_NE(ErrorOf([&] { s.Floats("updates"); }).find("another type"), std::string::npos);
  EXPECT_NE(ErrorOf([&] { s.Floats("net", 4); }).find("expected 4"), std::string::npos);
  EXPECT_EQ(s.Floats("net", 3).size(), 3U);
  StateFile twice("x");
  twice.PutInt("a", 1);
  EXPECT_THROW(twice.PutInt("a", 2), std::invalid_argument);
}

}  // namespace
}  // namespace rl
