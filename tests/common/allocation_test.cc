// The receive path's hot calls allocate nothing once warm: decoding a stream of messages whose
// arrays shrink to nothing and grow back into one reused object (every type of lcmtypes/), and
// signing and checking MACs. A binary of its own, since the count interposes on malloc for the
// whole process (tests/nn/allocation_counter.h).
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "common/message_auth.h"
#include "common/messages.h"
#include "rlmsg/all_types.hpp"
#include "tests/common/schema_message.h"
#include "tests/nn/allocation_counter.h"

namespace rl {
namespace {

template <class Msg>
void CheckNoAllocationOnceWarm() {
  const std::string type = Msg::getTypeName();
  SCOPED_TRACE(type);
  std::vector<std::vector<uint8_t>> stream;
  for (const int64_t n : {7, 0, 3, 0, 7, 1, 0, 7}) {
    stream.push_back(SchemaMessage(type, Msg::getHash(), n, static_cast<int>(n)));
  }
  Msg msg{};
  for (const auto& m : stream) ASSERT_EQ(Decode(m.data(), m.size(), &msg), nullptr);  // warm-up
  const int64_t before = nn::testing::AllocationCount();
  for (int round = 0; round < 10; ++round) {
    for (const auto& m : stream) ASSERT_EQ(Decode(m.data(), m.size(), &msg), nullptr);
  }
  EXPECT_EQ(nn::testing::AllocationCount() - before, 0);
}

TEST(AllocationTest, DecodingShrinkingAndRegrowingArraysAllocatesNothingOnceWarm) {
  if (!nn::testing::AllocationCountingAvailable()) GTEST_SKIP() << "no allocation count here";
#define RL_CHECK_TYPE(type) CheckNoAllocationOnceWarm<rlmsg::type>();
  RLMSG_ALL_TYPES(RL_CHECK_TYPE)
#undef RL_CHECK_TYPE
}

// Signing and checking: once a channel's key is derived, no message allocates, whatever its
// sender, incarnation or sequence number (a forger's choice), good MAC or bad.
TEST(AllocationTest, SigningAndCheckingMacsAllocatesNothingOnceAChannelsKeyIsKept) {
  if (!nn::testing::AllocationCountingAvailable()) GTEST_SKIP() << "no allocation count here";
  MessageAuthenticator signer(std::string(kKeyBytes, 'k'));
  MessageAuthenticator receiver(std::string(kKeyBytes, 'k'));
  // Messages laid out as MacOffset() says, senders of several lengths, 2 KB bodies.
  std::vector<std::vector<uint8_t>> messages;
  std::vector<size_t> offsets;
  for (const std::string sender : {"actor-1", "replay", "actor-12345", "xy"}) {
    const size_t at = MacOffset(sender.size());
    std::vector<uint8_t> m(at + kMacBytes + 2048, 0x33);
    m[16] = m[17] = m[18] = 0;
    m[19] = static_cast<uint8_t>(sender.size() + 1);
    std::copy(sender.begin(), sender.end(), m.begin() + 20);
    m[20 + sender.size()] = 0;
    std::fill(m.begin() + static_cast<ptrdiff_t>(at),
              m.begin() + static_cast<ptrdiff_t>(at + kMacBytes), 0);
    messages.push_back(m);
    offsets.push_back(at);
  }
  auto round = [&](int r) {
    for (size_t i = 0; i < messages.size(); ++i) {
      std::vector<uint8_t>& m = messages[i];
      const size_t at = offsets[i];
      m[at - 1] = static_cast<uint8_t>(r);   // incarnation
      m[at - 17] = static_cast<uint8_t>(r);  // seq
      std::fill(m.begin() + static_cast<ptrdiff_t>(at),
                m.begin() + static_cast<ptrdiff_t>(at + kMacBytes), 0);
      ASSERT_TRUE(signer.Sign("RL_TRANSITIONS", m.data(), m.size(), at));
      ASSERT_EQ(receiver.Verify("RL_TRANSITIONS", m.data(), m.size(), at), nullptr);
      // Forged: a MAC of its own, under a sender name no one used before.
      m[at] ^= 1;
      m[20] = static_cast<uint8_t>('A' + r % 26);
      m[21] = static_cast<uint8_t>('A' + r / 26);
      ASSERT_STREQ(receiver.Verify("RL_TRANSITIONS", m.data(), m.size(), at), "wrong MAC");
    }
  };
  round(0);  // derives the channel's key on both sides
  const int64_t before = nn::testing::AllocationCount();
  for (int r = 1; r < 50; ++r) round(r);
  EXPECT_EQ(nn::testing::AllocationCount() - before, 0);
}

}  // namespace
}  // namespace rl
