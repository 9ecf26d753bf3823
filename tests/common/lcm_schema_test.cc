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
  for (const char* type :
       {"header_t", "transition_batch_t", "sample_batch_t", "sample_request_t", "priority_update_t",
        "flow_control_t", "weights_chunk_t", "checkpoint_t", "eval_result_t", "stats_actor_t",
        "stats_replay_t", "stats_learner_t", "stats_evaluator_t"}) {
    ASSERT_EQ(LcmSchemas().count(type), 1u) << type;
    EXPECT_EQ(LcmSchemas().at(type).package, "rlmsg") << type;
  }
  EXPECT_STREQ(PrescanEncoded("no_such_t", nullptr, 0), "no schema");
}

TEST(LcmSchemaTest, PrescanAgreesWithTheEncodingOfEveryType) {
  rlmsg::transition_batch_t t{};
  t.header.sender = "actor-1";
  t.count = 2;
  t.obs_size = 0;
  t.height = t.width = 2;
  t.stack = 2;
  t.num_frames = 3;
  t.frame_id = {0, 1, 2};
  t.num_bytes = 12;
  t.frames.assign(12, 7);
  t.num_refs = 4;
  t.obs_frames = t.next_obs_frames = {0, 1, 1, 2};
  t.action_width = 3;
  t.num_action_values = 6;
  t.action.assign(6, 0.5f);
  t.reward = t.discount = t.priority = {1, 0};
  t.episode_id = {4, 4};
  ExpectPrescanAgrees(t);

  rlmsg::sample_batch_t s{};
  s.requester = "learner";
  s.count = 1;
  s.obs_size = 3;
  s.num_values = 3;
  s.obs = s.next_obs = {1, 2, 3};
  s.action_width = 1;
  s.num_action_values = 1;
  s.action = {2};
  s.reward = s.discount = s.weight = {1};
  s.index = {9};
  ExpectPrescanAgrees(s);

  rlmsg::weights_chunk_t w{};
  w.architecture = "linear(2,1)";
  w.count = 3;
  w.data = {1, 2, 3};
  ExpectPrescanAgrees(w);

  rlmsg::priority_update_t p{};
  p.count = 2;
  p.index = {1, 2};
  p.priority = {0.5f, 0.25f};
  ExpectPrescanAgrees(p);

  rlmsg::checkpoint_t c{};
  c.path = "/runs/x/ckpt.bin";
  ExpectPrescanAgrees(c);
  ExpectPrescanAgrees(rlmsg::sample_request_t{});
  ExpectPrescanAgrees(rlmsg::flow_control_t{});
  ExpectPrescanAgrees(rlmsg::eval_result_t{});
  ExpectPrescanAgrees(rlmsg::stats_actor_t{});
  ExpectPrescanAgrees(rlmsg::stats_replay_t{});
  ExpectPrescanAgrees(rlmsg::stats_learner_t{});
  ExpectPrescanAgrees(rlmsg::stats_evaluator_t{});
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
