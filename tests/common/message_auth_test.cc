#include "common/message_auth.h"

#include <openssl/core_names.h>
#include <openssl/evp.h>
#include <openssl/kdf.h>
#include <openssl/params.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "tests/common/error_of.h"
#include "tests/common/temp_dir.h"

namespace rl {
namespace {

namespace fs = std::filesystem;

class KeyFileTest : public TempDirTest {
 protected:
  std::string Write(const std::string& bytes, mode_t mode) {
    std::string path = (dir_ / "key").string();
    fs::remove(path);
    std::ofstream(path, std::ios::binary) << bytes;
    EXPECT_EQ(::chmod(path.c_str(), mode), 0);
    return path;
  }

  // The message of the error ReadKeyFile throws for `path`, which must be a std::runtime_error.
  static std::string ReadError(const std::string& path) {
    EXPECT_THROW(ReadKeyFile(path), std::runtime_error) << path;
    return ErrorOf([&] { ReadKeyFile(path); });
  }
};

TEST_F(KeyFileTest, ReadsAnOwnerOnlyKeyOfTheRightSize) {
  const std::string key(kKeyBytes, '\x07');
  EXPECT_EQ(ReadKeyFile(Write(key, 0600)), key);
  EXPECT_EQ(ReadKeyFile(Write(key, 0400)), key);
}

TEST_F(KeyFileTest, RefusesAKeyOthersMayReadAWrongSizeOrNoFile) {
  EXPECT_NE(ReadError(Write(std::string(kKeyBytes, 'a'), 0644)).find("others than its owner"),
            std::string::npos);
  EXPECT_NE(ReadError(Write(std::string(kKeyBytes - 1, 'a'), 0600)).find("holds 31 bytes"),
            std::string::npos);
  EXPECT_NE(ReadError(Write(std::string(kKeyBytes + 9, 'a'), 0600)).find("holds 33+ bytes"),
            std::string::npos);
  EXPECT_NE(ReadError((dir_ / "none").string()).find("none"), std::string::npos);
  EXPECT_NE(ReadError(dir_.string()).find("not a regular file"), std::string::npos);
}

// A message laid out as an encoded header_t begins (MacOffset()): fingerprint, run id, the
// sender, seq, utime, incarnation, MAC (zero), then a body.
std::vector<uint8_t> Message(int64_t seq, int64_t incarnation, size_t body = 60,
                             const std::string& sender = "actor-1") {
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

bool Same(const std::vector<uint8_t>& a, const std::vector<uint8_t>& b, size_t at) {
  return std::equal(a.begin() + at, a.begin() + at + kMacBytes, b.begin() + at);
}

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
  // Another key, another channel, a cut message.
  MessageAuthenticator other(std::string(kKeyBytes, 'o'));
  EXPECT_STREQ(other.Verify("CH", msg.data(), msg.size(), kAt), "wrong MAC");
  EXPECT_STREQ(auth.Verify("CH2", msg.data(), msg.size(), kAt), "wrong MAC");
  EXPECT_STREQ(auth.Verify("C", msg.data(), msg.size(), kAt), "wrong MAC");
  EXPECT_STREQ(auth.Verify("CH", msg.data(), kAt + kMacBytes - 1, kAt), "no room for a MAC");
  EXPECT_STREQ(auth.Verify("CH", msg.data(), msg.size(), MacOffset(0) - 1), "no room for a MAC");
  EXPECT_FALSE(auth.Sign("CH", msg.data(), kAt + 3, kAt));
  // Every bit of the message, the MAC's included, changed alone.
  for (size_t byte = 0; byte < msg.size(); ++byte) {
    for (int bit = 0; bit < 8; ++bit) {
      std::vector<uint8_t> changed = msg;
      changed[byte] ^= static_cast<uint8_t>(1 << bit);
      const char* why = auth.Verify("CH", changed.data(), changed.size(), kAt);
      ASSERT_NE(why, nullptr) << "byte " << byte << " bit " << bit;
    }
  }
  // Another sender of the same length, and a MAC of zeros.
  std::vector<uint8_t> other_sender = msg;
  other_sender[26] = '2';  // "actor-2"
  EXPECT_STREQ(auth.Verify("CH", other_sender.data(), other_sender.size(), kAt), "wrong MAC");
  std::vector<uint8_t> zero = msg;
  std::fill(zero.begin() + kAt, zero.begin() + kAt + kMacBytes, 0);
  EXPECT_STREQ(auth.Verify("CH", zero.data(), zero.size(), kAt), "no MAC");
  EXPECT_EQ(auth.Verify("CH", msg.data(), msg.size(), kAt), nullptr);  // failures kept nothing
}

// The tag, computed independently with OpenSSL's one-shot calls: the channel's key by HKDF
// through EVP_PKEY, and AES-256-GMAC over the message (MAC zero) through EVP_Q_mac, with the nonce
// of message_auth.h (seq | incarnation | sender zero-padded to 64 bytes).
std::vector<uint8_t> ReferenceTag(const std::string& run_key, const std::string& channel,
                                  const std::vector<uint8_t>& msg, int64_t seq, int64_t incarnation,
                                  const std::string& sender) {
  unsigned char key[32];
  size_t key_size = sizeof(key);
  const std::string info = "rl-gmac-v2" + channel;
  EVP_PKEY_CTX* kdf = EVP_PKEY_CTX_new_id(EVP_PKEY_HKDF, nullptr);
  EXPECT_TRUE(kdf != nullptr && EVP_PKEY_derive_init(kdf) == 1 &&
              EVP_PKEY_CTX_set_hkdf_md(kdf, EVP_sha256()) == 1 &&
              EVP_PKEY_CTX_set1_hkdf_key(kdf,
                                         reinterpret_cast<const unsigned char*>(run_key.data()),
                                         static_cast<int>(run_key.size())) == 1 &&
              EVP_PKEY_CTX_add1_hkdf_info(kdf, reinterpret_cast<const unsigned char*>(info.data()),
                                          static_cast<int>(info.size())) == 1 &&
              EVP_PKEY_derive(kdf, key, &key_size) == 1);
  EVP_PKEY_CTX_free(kdf);
  unsigned char nonce[80] = {};
  for (int i = 0; i < 8; ++i) {
    nonce[i] = static_cast<unsigned char>(static_cast<uint64_t>(seq) >> (56 - 8 * i));
    nonce[8 + i] = static_cast<unsigned char>(static_cast<uint64_t>(incarnation) >> (56 - 8 * i));
  }
  std::copy(sender.begin(), sender.end(), nonce + 16);
  char cipher[] = "AES-256-GCM";
  const OSSL_PARAM params[] = {OSSL_PARAM_construct_utf8_string(OSSL_MAC_PARAM_CIPHER, cipher, 0),
                               OSSL_PARAM_construct_octet_string(OSSL_MAC_PARAM_IV, nonce, 80),
                               OSSL_PARAM_construct_end()};
  std::vector<uint8_t> tag(kMacBytes);
  size_t tag_size = 0;
  EXPECT_NE(EVP_Q_mac(nullptr, "GMAC", nullptr, nullptr, params, key, key_size, msg.data(),
                      msg.size(), tag.data(), tag.size(), &tag_size),
            nullptr);
  EXPECT_EQ(tag_size, kMacBytes);
  return tag;
}

TEST(MessageAuthenticatorTest, TagsAreOpenSslsAes256GmacUnderTheChannelsHkdfKey) {
  std::string run_key(kKeyBytes, '\0');
  for (size_t i = 0; i < kKeyBytes; ++i) run_key[i] = static_cast<char>(i * 7 + 1);
  MessageAuthenticator auth(run_key);
  for (const auto& [channel, sender, body] :
       {std::tuple<std::string, std::string, size_t>{"RL_TRANSITIONS", "actor-1", 60},
        {"RL_SAMPLES", "replay", 0},
        {"X", std::string(kMaxSenderBytes, 's'), 5000}}) {
    const int64_t seq = 0x0102030405060708, incarnation = 1'700'000'000'000'000;
    std::vector<uint8_t> msg = Message(seq, incarnation, body, sender);
    const size_t at = MacOffset(sender.size());
    const std::vector<uint8_t> want = ReferenceTag(run_key, channel, msg, seq, incarnation, sender);
    ASSERT_TRUE(auth.Sign(channel, msg.data(), msg.size(), at)) << channel;
    EXPECT_TRUE(std::equal(want.begin(), want.end(), msg.begin() + static_cast<ptrdiff_t>(at)))
        << channel;
  }
  // And one tag written out, so that the wire format cannot change unnoticed (a new format is a
  // new label).
  std::vector<uint8_t> msg = Message(1, 2);
  ASSERT_TRUE(auth.Sign("RL_FLOW", msg.data(), msg.size(), kAt));
  char hex[2 * kMacBytes + 1];
  for (size_t i = 0; i < kMacBytes; ++i) std::snprintf(hex + 2 * i, 3, "%02x", msg[kAt + i]);
  EXPECT_STREQ(hex, "37b86fbb684308a00a12469533c2cc90");
}

// The same body under another sequence number, incarnation or sender (another nonce) gets another
// MAC, and each verifies only as itself.
TEST(MessageAuthenticatorTest, EachSequenceNumberIncarnationAndSenderHasItsOwnMac) {
  MessageAuthenticator signer(std::string(kKeyBytes, 'k'));
  MessageAuthenticator receiver(std::string(kKeyBytes, 'k'));
  std::vector<std::vector<uint8_t>> signed_msgs;
  for (const auto& [seq, incarnation, sender] :
       std::vector<std::tuple<int64_t, int64_t, std::string>>{{0, 1000, "actor-1"},
                                                              {1, 1000, "actor-1"},
                                                              {0, 2000, "actor-1"},
                                                              {0, 1000, "actor-2"}}) {
    signed_msgs.push_back(Message(seq, incarnation, 60, sender));
    ASSERT_TRUE(signer.Sign("CH", signed_msgs.back().data(), signed_msgs.back().size(), kAt));
  }
  for (size_t i = 0; i < signed_msgs.size(); ++i) {
    EXPECT_EQ(receiver.Verify("CH", signed_msgs[i].data(), signed_msgs[i].size(), kAt), nullptr);
    for (size_t j = i + 1; j < signed_msgs.size(); ++j) {
      EXPECT_FALSE(Same(signed_msgs[i], signed_msgs[j], kAt)) << i << " " << j;
    }
  }
  // A MAC moved onto another sequence number does not verify.
  std::vector<uint8_t> moved = Message(5, 1000);
  std::copy(signed_msgs[0].begin() + kAt, signed_msgs[0].begin() + kAt + kMacBytes,
            moved.begin() + kAt);
  EXPECT_STREQ(receiver.Verify("CH", moved.data(), moved.size(), kAt), "wrong MAC");
}

// Past kMaxChannels channels, keys are derived per message: still right.
TEST(MessageAuthenticatorTest, VerifiesPastTheKeptChannels) {
  MessageAuthenticator signer(std::string(kKeyBytes, 'k'));
  MessageAuthenticator receiver(std::string(kKeyBytes, 'k'));
  for (size_t c = 0; c < MessageAuthenticator::kMaxChannels + 10; ++c) {
    const std::string channel = "CH" + std::to_string(c);
    std::vector<uint8_t> msg = Message(0, 1000);
    ASSERT_TRUE(signer.Sign(channel, msg.data(), msg.size(), kAt));
    ASSERT_EQ(receiver.Verify(channel, msg.data(), msg.size(), kAt), nullptr) << c;
    ASSERT_STREQ(receiver.Verify("other", msg.data(), msg.size(), kAt), "wrong MAC") << c;
  }
}

TEST(MessageAuthenticatorTest, RefusesAKeyOfTheWrongSizeAndSendersUnfitForTheNonce) {
  EXPECT_THROW(MessageAuthenticator(std::string(16, 'k')), std::invalid_argument);
  MessageAuthenticator auth(std::string(kKeyBytes, 'k'));
  const std::string long_sender(kMaxSenderBytes + 1, 's');
  std::vector<uint8_t> msg = Message(0, 1000, 60, long_sender);
  EXPECT_FALSE(auth.Sign("CH", msg.data(), msg.size(), MacOffset(long_sender.size())));
  msg[kAt + 1] = 1;  // a MAC that is not zero
  EXPECT_STREQ(auth.Verify("CH", msg.data(), msg.size(), MacOffset(long_sender.size())),
               "a sender name unfit for a nonce");
  std::vector<uint8_t> spaced = Message(0, 1000, 60, "act or");
  EXPECT_FALSE(auth.Sign("CH", spaced.data(), spaced.size(), MacOffset(6)));
}

TEST(WireHeaderTest, ReadsTheHeaderFromRawBytesAndRefusesWhatCannotBeOne) {
  std::vector<uint8_t> msg = Message(42, 777, 10);
  for (int i = 0; i < 8; ++i) msg[8 + i] = static_cast<uint8_t>(i == 7 ? 9 : 0);  // run id 9
  WireHeader h;
  ASSERT_EQ(ReadWireHeader(msg.data(), msg.size(), &h), nullptr);
  EXPECT_EQ(h.run_id, 9);
  EXPECT_EQ(h.sender, "actor-1");
  EXPECT_EQ(h.seq, 42);
  EXPECT_EQ(h.incarnation, 777);
  EXPECT_EQ(h.mac_offset, kAt);
  EXPECT_STREQ(ReadWireHeader(msg.data(), kAt + kMacBytes - 1, &h), "too short for a header");
  EXPECT_STREQ(ReadWireHeader(msg.data(), 20, &h), "too short for a header");
  for (const std::string& sender : {std::string(""), std::string(kMaxSenderBytes + 1, 'a'),
                                    std::string("a b"), std::string("a\tb")}) {
    const std::vector<uint8_t> bad = Message(0, 0, 100, sender);
    EXPECT_NE(ReadWireHeader(bad.data(), bad.size(), &h), nullptr) << sender;
  }
  std::vector<uint8_t> long_length = msg;
  long_length[19] = 200;  // a sender length past the name's end
  EXPECT_NE(ReadWireHeader(long_length.data(), long_length.size(), &h), nullptr);
  std::vector<uint8_t> no_nul = msg;
  no_nul[27] = 'x';
  EXPECT_NE(ReadWireHeader(no_nul.data(), no_nul.size(), &h), nullptr);
}

}  // namespace
}  // namespace rl
