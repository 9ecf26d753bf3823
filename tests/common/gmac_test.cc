#include "common/gmac.h"

#include <openssl/evp.h>

#include <algorithm>
#include <array>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

namespace rl {
namespace {

using Tag = std::array<uint8_t, Gmac::kTagBytes>;

std::string Hex(const Tag& tag) {
  std::string out;
  char byte[3];
  for (uint8_t b : tag) {
    std::snprintf(byte, sizeof(byte), "%02x", b);
    out += byte;
  }
  return out;
}

// The reference: OpenSSL's AES-256-GCM over the message as associated data, nothing encrypted.
Tag OpenSslTag(const uint8_t* key, const uint8_t* nonce, const uint8_t* data, size_t size) {
  EVP_CIPHER_CTX* c = EVP_CIPHER_CTX_new();
  Tag tag{};
  int n = 0;
  uint8_t none[16];
  EXPECT_EQ(EVP_EncryptInit_ex(c, EVP_aes_256_gcm(), nullptr, key, nonce), 1);
  if (size > 0) {
    EXPECT_EQ(EVP_EncryptUpdate(c, nullptr, &n, data, static_cast<int>(size)), 1);
  }
  EXPECT_EQ(EVP_EncryptFinal_ex(c, none, &n), 1);
  EXPECT_EQ(EVP_CIPHER_CTX_ctrl(c, EVP_CTRL_GCM_GET_TAG, 16, tag.data()), 1);
  EVP_CIPHER_CTX_free(c);
  return tag;
}

Tag GmacTag(Gmac* gmac, const uint8_t* nonce, const uint8_t* data, size_t size) {
  Tag tag{};
  EXPECT_TRUE(gmac->Start(nonce));
  gmac->Update(data, size);
  EXPECT_TRUE(gmac->Finish(tag.data()));
  return tag;
}

std::vector<uint8_t> RandomBytes(std::mt19937_64* rng, size_t size) {
  std::vector<uint8_t> out(size);
  for (uint8_t& b : out) b = static_cast<uint8_t>((*rng)());
  return out;
}

TEST(GmacTest, KnownAnswerOfTheGcmSpecification) {
  // McGrew and Viega's GCM test case 13: AES-256, key and nonce zero, nothing to authenticate.
  const uint8_t key[32] = {};
  const uint8_t nonce[12] = {};
  Gmac gmac;
  ASSERT_TRUE(gmac.SetKey(key));
  EXPECT_EQ(Hex(GmacTag(&gmac, nonce, nullptr, 0)), "530f8afbc74536b9a963b4f1c4cb738b");
}

TEST(GmacTest, MatchesOpenSslOnEveryLengthTo2KBAndAPixelBatch) {
  std::mt19937_64 rng(7);
  const std::vector<uint8_t> key = RandomBytes(&rng, 32);
  const std::vector<uint8_t> data = RandomBytes(&rng, 240'000);
  Gmac gmac;
  ASSERT_TRUE(gmac.SetKey(key.data()));
  RecordProperty("ghash", Gmac::Accelerated() ? "kernel" : "OpenSSL");
  std::vector<size_t> sizes;
  for (size_t size = 0; size <= 2048; ++size) sizes.push_back(size);
  for (size_t size : {7'200, 230'000, 239'993}) sizes.push_back(size);
  for (size_t size : sizes) {
    const std::vector<uint8_t> nonce = RandomBytes(&rng, 12);
    const uint8_t* at = data.data() + size % 7;  // unaligned starts too
    ASSERT_EQ(Hex(GmacTag(&gmac, nonce.data(), at, size)),
              Hex(OpenSslTag(key.data(), nonce.data(), at, size)))
        << size << " bytes (" << (Gmac::Accelerated() ? "kernel" : "OpenSSL") << ")";
  }
}

TEST(GmacTest, AnySplitOfAMessageGivesItsTag) {
  std::mt19937_64 rng(11);
  const std::vector<uint8_t> key = RandomBytes(&rng, 32);
  const std::vector<uint8_t> nonce = RandomBytes(&rng, 12);
  const std::vector<uint8_t> data = RandomBytes(&rng, 9'000);
  Gmac gmac;
  ASSERT_TRUE(gmac.SetKey(key.data()));
  const std::string whole = Hex(GmacTag(&gmac, nonce.data(), data.data(), data.size()));
  for (int trial = 0; trial < 200; ++trial) {
    ASSERT_TRUE(gmac.Start(nonce.data()));
    size_t at = 0;
    while (at < data.size()) {
      // Pieces from 0 bytes to past a whole stride (512 bytes), mostly not block-aligned.
      const size_t piece = std::min<size_t>(data.size() - at, rng() % 700);
      gmac.Update(data.data() + at, piece);
      at += piece;
    }
    Tag tag{};
    ASSERT_TRUE(gmac.Finish(tag.data()));
    ASSERT_EQ(Hex(tag), whole) << "trial " << trial;
  }
}

TEST(GmacTest, KeyNonceAndEveryBitChangeTheTag) {
  std::mt19937_64 rng(13);
  std::vector<uint8_t> key = RandomBytes(&rng, 32);
  std::vector<uint8_t> nonce = RandomBytes(&rng, 12);
  std::vector<uint8_t> data = RandomBytes(&rng, 1'500);
  Gmac gmac;
  ASSERT_TRUE(gmac.SetKey(key.data()));
  const std::string base = Hex(GmacTag(&gmac, nonce.data(), data.data(), data.size()));
  for (size_t bit = 0; bit < data.size() * 8; bit += 37) {
    data[bit / 8] ^= static_cast<uint8_t>(1u << (bit % 8));
    EXPECT_NE(Hex(GmacTag(&gmac, nonce.data(), data.data(), data.size())), base) << bit;
    data[bit / 8] ^= static_cast<uint8_t>(1u << (bit % 8));
  }
  // A zero byte appended is another message (the length block binds the length).
  data.push_back(0);
  EXPECT_NE(Hex(GmacTag(&gmac, nonce.data(), data.data(), data.size())), base);
  data.pop_back();
  nonce[11] ^= 1;
  EXPECT_NE(Hex(GmacTag(&gmac, nonce.data(), data.data(), data.size())), base);
  nonce[11] ^= 1;
  key[0] ^= 1;
  ASSERT_TRUE(gmac.SetKey(key.data()));
  EXPECT_NE(Hex(GmacTag(&gmac, nonce.data(), data.data(), data.size())), base);
}

TEST(GmacTest, RefusesToStartWithoutAKey) {
  Gmac gmac;
  const uint8_t nonce[12] = {};
  EXPECT_FALSE(gmac.Start(nonce));
  Tag tag{};
  EXPECT_FALSE(gmac.Finish(tag.data()));
}

}  // namespace
}  // namespace rl
