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

}  // namespace
}  // namespace rl
