#include "common/messages.h"

#include <cmath>
#include <vector>

#include <gtest/gtest.h>

namespace rl {
namespace {

template <class Msg>
std::vector<uint8_t> Encode(Msg m) {
  m.header.sender = "test";
  std::vector<uint8_t> bytes(static_cast<size_t>(m.getEncodedSize()));
  m.encode(bytes.data(), 0, static_cast<int>(bytes.size()));
  return bytes;
}

// Prescan must accept every well-formed message and refuse every shorter prefix of it.
template <class Msg>
void ExpectPrescanMatchesTheEncoding(const Msg& m) {
  const auto bytes = Encode(m);
  EXPECT_EQ(Prescan(&m, bytes.data(), bytes.size()), nullptr);
  for (size_t cut = 0; cut < bytes.size(); cut += 7) {
    EXPECT_NE(Prescan(&m, bytes.data(), cut), nullptr) << "prefix of " << cut << " bytes";
  }
}

TEST(PrescanTest, AgreesWithTheEncodingOfATransitionBatch) {
  rlmsg::transition_batch_t m{};
  m.header.sender = "test";
  m.obs_size = 3;
  m.count = 5;
  m.num_values = 15;
  m.obs.assign(15, 1.0f);
  m.next_obs.assign(15, 2.0f);
  m.action.assign(5, 1);
  m.reward.assign(5, 0.5f);
  m.discount.assign(5, 0.9f);
  m.episode_id.assign(5, 3);
  m.priority.assign(5, 0.0f);
  ExpectPrescanMatchesTheEncoding(m);
  EXPECT_EQ(Validate(m), nullptr);
}

TEST(PrescanTest, AgreesWithTheEncodingOfASampleBatch) {
  rlmsg::sample_batch_t m{};
  m.header.sender = "test";
  m.requester = "learner";
  m.obs_size = 2;
  m.count = 4;
  m.num_values = 8;
  m.obs.assign(8, 1.0f);
  m.next_obs.assign(8, 2.0f);
  m.action.assign(4, 0);
  m.reward.assign(4, 0.5f);
  m.discount.assign(4, 0.9f);
  m.index.assign(4, 11);
  m.weight.assign(4, 1.0f);
  ExpectPrescanMatchesTheEncoding(m);
  EXPECT_EQ(Validate(m), nullptr);
}

TEST(PrescanTest, AgreesWithTheEncodingOfAWeightsChunk) {
  rlmsg::weights_chunk_t m{};
  m.header.sender = "test";
  m.version = 3;
  m.architecture = "linear(4,2)";
  m.total_size = 10;
  m.chunk_index = 0;
  m.num_chunks = 1;
  m.offset = 0;
  m.count = 10;
  m.data.assign(10, 0.25f);
  m.crc32 = 12345;
  ExpectPrescanMatchesTheEncoding(m);
  EXPECT_EQ(Validate(m), nullptr);
}

TEST(ValidateTest, RefusesAChunkOutsideItsBufferAndAnInconsistentBatch) {
  rlmsg::weights_chunk_t w{};
  w.header.sender = "learner";
  w.version = 1;
  w.architecture = "x";
  w.total_size = 10;
  w.num_chunks = 1;
  w.offset = 5;
  w.count = 6;
  w.data.assign(6, 0.0f);
  EXPECT_NE(Validate(w), nullptr);
  rlmsg::transition_batch_t t{};
  t.header.sender = "actor-0";
  t.obs_size = 4;
  t.count = 2;
  t.num_values = 7;
  EXPECT_NE(Validate(t), nullptr);
  rlmsg::sample_request_t r{};
  r.header.sender = "learner";
  r.batch_size = 0;
  EXPECT_NE(Validate(r), nullptr);
  rlmsg::flow_control_t f{};
  f.header.sender = "replay";
  f.insert_allowed = 3;
  EXPECT_NE(Validate(f), nullptr);
}

}  // namespace
}  // namespace rl
