#include "common/state_file.h"

#include <gtest/gtest.h>

#include "common/atomic_file.h"
#include "tests/common/error_of.h"
#include "tests/common/temp_dir.h"

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

TEST(StateFileTest, RoundTripsEverySectionThroughAFile) {
  const TempDir dir;
  const fs::path path = dir / "state.bin";
  Sample().Save(path.string());
  const StateFile s = StateFile::Load(path.string(), "learner td3");
  EXPECT_EQ(std::vector<float>(s.Floats("net").begin(), s.Floats("net").end()),
            (std::vector<float>{1.5f, -2.0f, 3.25f}));
  EXPECT_EQ(s.Int("updates"), 42);
  EXPECT_EQ(s.Text("net.arch"), "linear(3,1)");
  EXPECT_TRUE(s.Has("net"));
  EXPECT_FALSE(s.Has("other"));
}

// Found by fuzz_state_file: parsing an empty section copied from a null vector (UB under UBSan).
TEST(StateFileTest, RoundTripsEmptySections) {
  StateFile s("learner td3");
  s.PutFloats("none", std::span<const float>());
  s.PutInts("no_ints", std::span<const int64_t>());
  const StateFile back = StateFile::Parse(s.Serialize(), "learner td3");
  EXPECT_TRUE(back.Has("none"));
  EXPECT_TRUE(back.Floats("none").empty());
  EXPECT_TRUE(back.Has("no_ints"));
  EXPECT_TRUE(back.Ints("no_ints").empty());
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

TEST(StateStreamTest, WritesTheSameFormatWithoutCopyingAndParsesInPlace) {
  const std::vector<float> floats = {1.5f, -2.0f, 3.25f};
  const std::vector<uint8_t> first = {1, 2, 3};
  const std::vector<uint8_t> second = {4, 5};
  const std::vector<double> doubles = {0.25, 1e300};
  StateStream out("replay snapshot");
  out.AddFloats("net", floats);
  out.PutInt("updates", 42);
  out.PutText("net.arch", "linear(3,1)");
  out.AddBytes("frames", first);
  out.AddPiece(second.data(), second.size());
  out.AddDoubles("values", doubles);
  EXPECT_THROW(out.PutInt("net", 1), std::invalid_argument);
  const std::string bytes = out.Serialize();
  EXPECT_EQ(static_cast<int64_t>(bytes.size()), out.size());

  const StateView view = StateView::Parse(bytes, "replay snapshot");
  std::vector<uint8_t> frames(5);
  view.Copy<uint8_t>("frames", frames);
  EXPECT_EQ(frames, (std::vector<uint8_t>{1, 2, 3, 4, 5}));
  std::vector<double> values(2);
  view.Copy<double>("values", values);
  EXPECT_EQ(values, doubles);
  EXPECT_EQ(view.Int("updates"), 42);
  EXPECT_EQ(view.Text("net.arch"), "linear(3,1)");
  EXPECT_EQ(view.Count<float>("net"), 3);
  std::vector<float> four(4);
  EXPECT_NE(ErrorOf([&] { view.Copy<float>("net", four); }).find("expected 4"), std::string::npos);
  EXPECT_NE(ErrorOf([&] { view.Count<int64_t>("net"); }).find("another type"), std::string::npos);
  EXPECT_NE(ErrorOf([&] { view.Ints("updates", 0); }).find("at most 0"), std::string::npos);
  // StateFile reads the sections it holds, and names the ones it does not.
  EXPECT_NE(ErrorOf([&] { StateFile::Parse(bytes, "replay snapshot"); }).find("'frames'"),
            std::string::npos);
  StateStream small("learner td3");
  small.AddFloats("net", floats);
  EXPECT_EQ(StateFile::Parse(small.Serialize(), "learner td3").Floats("net", 3)[2], 3.25f);
}

TEST(StateStreamTest, AMappedFileIsCheckedAsBytesAre) {
  const TempDir dir;
  const fs::path path = dir / "state.bin";
  StateStream out("replay snapshot");
  out.PutInt("size", 7);
  AtomicFileStream file(path.string());
  ASSERT_TRUE(file.Open() && out.Write(&file) && file.Commit()) << file.ErrorMessage("state");
  EXPECT_EQ(file.bytes_written(), out.size());
  EXPECT_EQ(StateView::Map(path.string(), "replay snapshot").Int("size"), 7);
  EXPECT_NE(
      ErrorOf([&] { StateView::Map(path.string(), "other"); }).find(path.string() + " refused"),
      std::string::npos);
  std::ofstream(path, std::ios::trunc) << "";
  EXPECT_NE(ErrorOf([&] { StateView::Map(path.string(), "x"); }).find("bad magic or too short"),
            std::string::npos);
  fs::remove(path);
  EXPECT_NE(ErrorOf([&] { StateView::Map(path.string(), "x"); }).find("cannot read state"),
            std::string::npos);
  // Every prefix and every flipped byte of a file is refused, never read past its end.
  const std::string bytes = out.Serialize();
  for (size_t n = 0; n < bytes.size(); ++n) {
    EXPECT_THROW(StateView::Parse(bytes.substr(0, n), "replay snapshot"), std::runtime_error);
    std::string flipped = bytes;
    flipped[n] = static_cast<char>(flipped[n] ^ 1);
    EXPECT_THROW(StateView::Parse(flipped, "replay snapshot"), std::runtime_error);
  }
}

}  // namespace
}  // namespace rl
