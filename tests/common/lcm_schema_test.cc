// The schemas read from the .lcm files: the parser's grammar and errors, and the prescan they
// drive against real encodings of every message type.
#include "common/lcm_schema.h"
#include "common/message_auth.h"

#include <algorithm>
#include <cstdint>
#include <iterator>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "common/message_examples.h"
#include "common/messages.h"

namespace rl {
namespace {

template <class Msg>
std::vector<uint8_t> Encode(const Msg& m) {
  std::vector<uint8_t> bytes(static_cast<size_t>(m.getEncodedSize()));
  m.encode(bytes.data(), 0, static_cast<int>(bytes.size()));
  return bytes;
}

// The prescan accepts the whole encoding, refuses every shorter prefix, and refuses a trailing
// byte.
template <class Msg>
void ExpectPrescanAgrees(const Msg& m) {
  std::vector<uint8_t> bytes = Encode(m);
  const std::string type = Msg::getTypeName();
  EXPECT_EQ(PrescanEncoded(type, bytes.data(), bytes.size()), nullptr) << type;
  for (size_t cut = 0; cut < bytes.size(); ++cut) {
    ASSERT_NE(PrescanEncoded(type, bytes.data(), cut), nullptr) << type << ", " << cut << " bytes";
  }
  bytes.push_back(0);
  EXPECT_STREQ(PrescanEncoded(type, bytes.data(), bytes.size()), "trailing bytes") << type;
}

TEST(LcmSchemaTest, ParsesFieldsArraysAndComments) {
  const LcmStruct s = ParseLcmStruct(R"(package demo;
// a comment with struct { ; } in it
/* a block
   comment */
struct thing_t {
  header_t header;
  int32_t  n;
  int16_t  m;
  float    grid[n][3][m];
  string   names[2];
  rlmsg.header_t others[n];
}
)",
                                     "thing_t.lcm");
  EXPECT_EQ(s.package, "demo");
  EXPECT_EQ(s.name, "thing_t");
  ASSERT_EQ(s.fields.size(), 6u);
  EXPECT_EQ(s.fields[0].type, "header_t");
  EXPECT_EQ(s.fields[3].name, "grid");
  EXPECT_EQ(s.fields[3].dims, (std::vector<std::string>{"n", "3", "m"}));
  EXPECT_EQ(s.fields[4].dims, (std::vector<std::string>{"2"}));
  EXPECT_EQ(s.fields[5].type, "rlmsg.header_t");
}

TEST(LcmSchemaTest, RefusesWhatItCannotReadWithTheFileName) {
  const auto error = [](const std::string& text) {
    try {
      ParseLcmStruct(text, "bad.lcm");
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_EQ(error("struct a { int32_t x }"), "bad.lcm: expected ';', got '}'");
  EXPECT_EQ(error("struct a { float v[n]; int32_t n; }"),
            "bad.lcm: dimension 'n' of 'v' is not an earlier integer field");
  EXPECT_EQ(error("struct a { float n; float v[n]; }"),
            "bad.lcm: dimension 'n' of 'v' is not an earlier integer field");
  EXPECT_EQ(error("struct a { const int32_t X = 1; }"), "bad.lcm: constants are not supported");
  EXPECT_EQ(error("struct a { } struct b { }"), "bad.lcm: unexpected 'struct' after the struct");
  EXPECT_EQ(error("struct a { int32_t x; "), "bad.lcm: expected } at the end of the file");
  EXPECT_EQ(error("struct a { int32_t x; } /* open"), "bad.lcm: unclosed comment");
  EXPECT_EQ(error("struct a { int32_t x$; }"), "bad.lcm: unexpected character '$'");
}

// Every type of lcmtypes/ is embedded, under its file's name.
TEST(LcmSchemaTest, EmbedsEveryMessageType) {
  size_t types = 0;
#define RL_EXPECT_EMBEDDED(type)                               \
  ASSERT_EQ(LcmSchemas().count(#type), 1u) << #type;           \
  EXPECT_EQ(LcmSchemas().at(#type).package, "rlmsg") << #type; \
  ++types;
  RLMSG_ALL_TYPES(RL_EXPECT_EMBEDDED)
#undef RL_EXPECT_EMBEDDED
  EXPECT_EQ(types, LcmSchemas().size());
  EXPECT_STREQ(PrescanEncoded("no_such_t", nullptr, 0), "no schema");
}

// Every message of common/channels.h, empty and as its example (every array filled), and the
// pixel kinds of the batches.
TEST(LcmSchemaTest, PrescanAgreesWithTheEncodingOfEveryType) {
#define RL_EXPECT_AGREES(type, constant, name, port) \
  ExpectPrescanAgrees(rlmsg::type{});                \
  ExpectPrescanAgrees(examples::Example<rlmsg::type>());
  RL_MESSAGES(RL_EXPECT_AGREES)
#undef RL_EXPECT_AGREES
  ExpectPrescanAgrees(examples::PixelTransitions(0, 2, 2, 2));
  ExpectPrescanAgrees(examples::PixelSamples(2, 2, 2, 2, 3));
}

// A forged length is refused from the bytes, before anything is sized from it.
TEST(LcmSchemaTest, PrescanRefusesForgedLengths) {
  rlmsg::priority_update_t p{};
  p.header.sender = "learner";
  p.count = 1;
  p.index = {1};
  p.priority = {0.5f};
  std::vector<uint8_t> bytes = Encode(p);
  // count sits right after the header.
  const size_t at = MacOffset(p.header.sender.size()) + kMacBytes;
  ASSERT_EQ(bytes[at + 3], 1);
  for (const uint32_t forged : {0x7fffffffu, 0x80000000u, 2u, 0u}) {
    for (int k = 0; k < 4; ++k)
      bytes[at + static_cast<size_t>(k)] = (forged >> (24 - 8 * k)) & 0xff;
    EXPECT_NE(PrescanEncoded("priority_update_t", bytes.data(), bytes.size()), nullptr) << forged;
  }
  // A string length of 0 (lcm strings carry their NUL) and one past the end.
  rlmsg::checkpoint_t c{};
  c.path = "abc";
  bytes = Encode(c);
  const size_t path_at = MacOffset(0) + kMacBytes;  // after a header with an empty sender
  ASSERT_EQ(bytes[path_at + 3], 4);
  bytes[path_at + 3] = 0;
  EXPECT_NE(PrescanEncoded("checkpoint_t", bytes.data(), bytes.size()), nullptr);
  bytes[path_at + 3] = 200;
  EXPECT_NE(PrescanEncoded("checkpoint_t", bytes.data(), bytes.size()), nullptr);
}

// A string with a NUL inside decodes (lcm-gen keeps every byte) but re-encodes shorter (the
// encoder stops at the first NUL), so a reply that echoes it would be sent with stale bytes at
// its end: refused, as is a string without its terminating NUL. Found by fuzz/fuzz_messages.
TEST(LcmSchemaTest, PrescanRefusesStringsWithANulInside) {
  rlmsg::checkpoint_t c{};
  c.header.sender = "learner";
  c.path = "abc";
  std::vector<uint8_t> bytes = Encode(c);
  ASSERT_EQ(PrescanEncoded("checkpoint_t", bytes.data(), bytes.size()), nullptr);
  const uint8_t path[] = {0, 0, 0, 4, 'a', 'b', 'c', 0};
  const size_t at = static_cast<size_t>(
      std::search(bytes.begin(), bytes.end(), std::begin(path), std::end(path)) - bytes.begin());
  ASSERT_LT(at, bytes.size());
  bytes[at + 5] = 0;  // "a\0c"
  EXPECT_STREQ(PrescanEncoded("checkpoint_t", bytes.data(), bytes.size()),
               "string with a NUL inside");
  rlmsg::checkpoint_t decoded{};
  EXPECT_STREQ(Decode(bytes.data(), bytes.size(), &decoded), "string with a NUL inside");
  bytes[at + 5] = 'b';
  bytes[at + 7] = 'd';  // no terminating NUL
  EXPECT_STREQ(PrescanEncoded("checkpoint_t", bytes.data(), bytes.size()),
               "string with a NUL inside");
}

}  // namespace
}  // namespace rl
