#include "common/message_auth.h"

#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

namespace rl {
namespace {

namespace fs = std::filesystem;

class KeyFileTest : public ::testing::Test {
 protected:
  KeyFileTest() : dir_(fs::temp_directory_path() / ("key_file_" + std::to_string(getpid()))) {
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  ~KeyFileTest() override { fs::remove_all(dir_); }

  std::string Write(const std::string& bytes, mode_t mode) {
    const std::string path = (dir_ / "key").string();
    fs::remove(path);
    std::ofstream(path, std::ios::binary) << bytes;
    EXPECT_EQ(::chmod(path.c_str(), mode), 0);
    return path;
  }

  // The error ReadKeyFile throws for `path` ("" when it throws none).
  static std::string ErrorOf(const std::string& path) {
    try {
      ReadKeyFile(path);
    } catch (const std::runtime_error& e) {
      return e.what();
    }
    return "";
  }

  fs::path dir_;
};

TEST_F(KeyFileTest, ReadsAnOwnerOnlyKeyOfTheRightSize) {
  const std::string key(kKeyBytes, '\x07');
  EXPECT_EQ(ReadKeyFile(Write(key, 0600)), key);
  EXPECT_EQ(ReadKeyFile(Write(key, 0400)), key);
}

TEST_F(KeyFileTest, RefusesAKeyOthersMayReadAWrongSizeOrNoFile) {
  EXPECT_NE(ErrorOf(Write(std::string(kKeyBytes, 'a'), 0644)).find("others than its owner"),
            std::string::npos);
  EXPECT_NE(ErrorOf(Write(std::string(kKeyBytes - 1, 'a'), 0600)).find("holds 31 bytes"),
            std::string::npos);
  EXPECT_NE(ErrorOf(Write(std::string(kKeyBytes + 9, 'a'), 0600)).find("holds 33+ bytes"),
            std::string::npos);
  EXPECT_NE(ErrorOf((dir_ / "none").string()).find("none"), std::string::npos);
  EXPECT_NE(ErrorOf(dir_.string()).find("not a regular file"), std::string::npos);
}

TEST(MessageAuthenticatorTest, SignsAndVerifiesAndRefusesWhatChanged) {
  MessageAuthenticator auth(std::string(kKeyBytes, 'k'));
  std::vector<uint8_t> msg(100, 0x5a);
  const size_t at = 40;
  std::fill(msg.begin() + at, msg.begin() + at + kMacBytes, 0);
  EXPECT_STREQ(auth.Verify(msg.data(), msg.size(), at), "no MAC");
  ASSERT_TRUE(auth.Sign(msg.data(), msg.size(), at));
  EXPECT_EQ(auth.Verify(msg.data(), msg.size(), at), nullptr);
  // Deterministic: the same bytes, the same MAC.
  std::vector<uint8_t> again(100, 0x5a);
  std::fill(again.begin() + at, again.begin() + at + kMacBytes, 0);
  ASSERT_TRUE(auth.Sign(again.data(), again.size(), at));
  EXPECT_EQ(again, msg);
  // Another key, a changed byte, a cut message.
  MessageAuthenticator other(std::string(kKeyBytes, 'o'));
  EXPECT_STREQ(other.Verify(msg.data(), msg.size(), at), "wrong MAC");
  msg[99] ^= 1;
  EXPECT_STREQ(auth.Verify(msg.data(), msg.size(), at), "wrong MAC");
  EXPECT_STREQ(auth.Verify(msg.data(), at + kMacBytes - 1, at), "no room for a MAC");
  EXPECT_FALSE(auth.Sign(msg.data(), at + 3, at));
}

TEST(MessageAuthenticatorTest, RefusesAKeyOfTheWrongSize) {
  EXPECT_THROW(MessageAuthenticator(std::string(16, 'k')), std::invalid_argument);
}

}  // namespace
}  // namespace rl
