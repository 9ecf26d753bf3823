#include "common/message_auth.h"

#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>
#include <utility>
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

// A message laid out as an encoded header_t begins (MacOffset()): fingerprint, run id, the
// sender "actor-1", seq, utime, incarnation, MAC (zero), then a body.
std::vector<uint8_t> Message(int64_t seq, int64_t incarnation, size_t body = 60) {
  const std::string sender = "actor-1";
  std::vector<uint8_t> m(MacOffset(sender.size()) + kMacBytes + body, 0x5a);
  const uint32_t len = static_cast<uint32_t>(sender.size() + 1);
  for (int i = 0; i < 4; ++i) m[16 + i] = static_cast<uint8_t>(len >> (24 - 8 * i));
  std::copy(sender.begin(), sender.end(), m.begin() + 20);
  m[20 + sender.size()] = 0;
  const size_t at = MacOffset(sender.size());
  for (int i = 0; i < 8; ++i) {
    m[at - 24 + i] = static_cast<uint8_t>(static_cast<uint64_t>(seq) >> (56 - 8 * i));
    m[at - 8 + i] = static_cast<uint8_t>(static_cast<uint64_t>(incarnation) >> (56 - 8 * i));
  }
  std::fill(m.begin() + at, m.begin() + at + kMacBytes, 0);
  return m;
}
const size_t kAt = MacOffset(7);

TEST(MessageAuthenticatorTest, SignsAndVerifiesAndRefusesWhatChanged) {
  MessageAuthenticator auth(std::string(kKeyBytes, 'k'));
  std::vector<uint8_t> msg = Message(3, 1000);
  EXPECT_STREQ(auth.Verify("CH", msg.data(), msg.size(), kAt), "no MAC");
  ASSERT_TRUE(auth.Sign("CH", msg.data(), msg.size(), kAt));
  EXPECT_EQ(auth.Verify("CH", msg.data(), msg.size(), kAt), nullptr);
  // Deterministic: the same bytes on the same channel, the same MAC, also from another instance.
  MessageAuthenticator same_key(std::string(kKeyBytes, 'k'));
  std::vector<uint8_t> again = Message(3, 1000);
  ASSERT_TRUE(same_key.Sign("CH", again.data(), again.size(), kAt));
  EXPECT_EQ(again, msg);
  // Another key, another channel, a changed byte in the body or in the header, a cut message.
  MessageAuthenticator other(std::string(kKeyBytes, 'o'));
  EXPECT_STREQ(other.Verify("CH", msg.data(), msg.size(), kAt), "wrong MAC");
  EXPECT_STREQ(auth.Verify("CH2", msg.data(), msg.size(), kAt), "wrong MAC");
  for (const size_t byte : {msg.size() - 1, kAt - 1, kAt - 9, kAt - 17, size_t{20}}) {
    std::vector<uint8_t> changed = msg;
    changed[byte] ^= 1;
    EXPECT_STREQ(auth.Verify("CH", changed.data(), changed.size(), kAt), "wrong MAC") << byte;
  }
  EXPECT_EQ(auth.Verify("CH", msg.data(), msg.size(), kAt), nullptr);  // failures kept nothing
  EXPECT_STREQ(auth.Verify("CH", msg.data(), kAt + kMacBytes - 1, kAt), "no room for a MAC");
  EXPECT_STREQ(auth.Verify("CH", msg.data(), msg.size(), MacOffset(0) - 1), "no room for a MAC");
  EXPECT_FALSE(auth.Sign("CH", msg.data(), kAt + 3, kAt));
}

// The same body under another sequence number or incarnation (another nonce, another stream key)
// gets another MAC, and each verifies only as itself; an older incarnation after a newer one
// still verifies (the Bus drops it as replayed), and does not displace the newer stream's key.
TEST(MessageAuthenticatorTest, EachSequenceNumberAndIncarnationHasItsOwnMac) {
  MessageAuthenticator signer(std::string(kKeyBytes, 'k'));
  MessageAuthenticator receiver(std::string(kKeyBytes, 'k'));
  std::vector<std::vector<uint8_t>> signed_msgs;
  for (const auto& [seq, incarnation] :
       std::vector<std::pair<int64_t, int64_t>>{{0, 1000}, {1, 1000}, {0, 2000}, {1, 2000}}) {
    signed_msgs.push_back(Message(seq, incarnation));
    ASSERT_TRUE(signer.Sign("CH", signed_msgs.back().data(), signed_msgs.back().size(), kAt));
  }
  for (size_t i = 0; i < signed_msgs.size(); ++i) {
    for (size_t j = i + 1; j < signed_msgs.size(); ++j) {
      EXPECT_FALSE(std::equal(signed_msgs[i].begin() + kAt,
                              signed_msgs[i].begin() + kAt + kMacBytes,
                              signed_msgs[j].begin() + kAt))
          << i << " " << j;
    }
  }
  for (const int k : {2, 3, 0, 1, 3}) {
    EXPECT_EQ(receiver.Verify("CH", signed_msgs[k].data(), signed_msgs[k].size(), kAt), nullptr)
        << k;
  }
  // A MAC moved onto another sequence number does not verify.
  std::vector<uint8_t> moved = Message(5, 2000);
  std::copy(signed_msgs[3].begin() + kAt, signed_msgs[3].begin() + kAt + kMacBytes,
            moved.begin() + kAt);
  EXPECT_STREQ(receiver.Verify("CH", moved.data(), moved.size(), kAt), "wrong MAC");
}

// Past kMaxStreams (channel, sender) pairs, keys are derived per message: still right.
TEST(MessageAuthenticatorTest, VerifiesPastTheKeptStreams) {
  MessageAuthenticator signer(std::string(kKeyBytes, 'k'));
  MessageAuthenticator receiver(std::string(kKeyBytes, 'k'));
  for (size_t c = 0; c < MessageAuthenticator::kMaxStreams + 10; ++c) {
    const std::string channel = "CH" + std::to_string(c);
    std::vector<uint8_t> msg = Message(0, 1000);
    ASSERT_TRUE(signer.Sign(channel, msg.data(), msg.size(), kAt));
    ASSERT_EQ(receiver.Verify(channel, msg.data(), msg.size(), kAt), nullptr) << c;
    ASSERT_STREQ(receiver.Verify("other", msg.data(), msg.size(), kAt), "wrong MAC") << c;
  }
}

TEST(MessageAuthenticatorTest, RefusesAKeyOfTheWrongSize) {
  EXPECT_THROW(MessageAuthenticator(std::string(16, 'k')), std::invalid_argument);
}

}  // namespace
}  // namespace rl
