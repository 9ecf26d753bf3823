#include "common/crc32.h"

#include <string>

#include <gtest/gtest.h>

namespace rl {
namespace {

TEST(Crc32Test, MatchesTheStandardCheckValue) {
  // The check value of CRC-32/ISO-HDLC for the ASCII digits "123456789".
  const std::string s = "123456789";
  EXPECT_EQ(Crc32(s.data(), s.size()), 0xCBF43926U);
}

TEST(Crc32Test, ContinuesAcrossSplits) {
  const std::string s = "the quick brown fox jumps over the lazy dog";
  const uint32_t whole = Crc32(s.data(), s.size());
  const uint32_t split = Crc32(s.data() + 10, s.size() - 10, Crc32(s.data(), 10));
  EXPECT_EQ(whole, split);
  EXPECT_EQ(Crc32(nullptr, 0), 0U);
}

TEST(Crc32Test, EightBytesAtATimeMatchesTheBytewiseDefinition) {
  // The reflected polynomial, one bit at a time.
  const auto reference = [](const std::string& s) {
    uint32_t crc = ~0U;
    for (unsigned char c : s) {
      crc ^= c;
      for (int k = 0; k < 8; ++k) crc = (crc & 1U) ? 0xEDB88320U ^ (crc >> 1) : crc >> 1;
    }
    return ~crc;
  };
  std::string s;
  for (int n = 0; n < 100; ++n) {
    EXPECT_EQ(Crc32(s.data(), s.size()), reference(s)) << n;
    // Any split, aligned or not.
    if (n > 3) {
      EXPECT_EQ(Crc32(s.data() + 3, s.size() - 3, Crc32(s.data(), 3)), reference(s));
    }
    s.push_back(static_cast<char>(n * 37 + 11));
  }
}

}  // namespace
}  // namespace rl
