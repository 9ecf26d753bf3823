#include "common/messages.h"
#include "common/message_auth.h"
#include "common/message_examples.h"

#include <algorithm>
#include <cmath>
#include <limits>
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

// A valid flat batch: `count` transitions of `obs_size` floats and `action_width` action values.
rlmsg::transition_batch_t FlatBatch(int count, int obs_size, int action_width) {
  return examples::FlatTransitions(0, count, obs_size, action_width);
}

TEST(ValidateTest, AcceptsAFlatBatchAndRefusesAnInconsistentOne) {
  rlmsg::transition_batch_t m = FlatBatch(5, 3, 1);
  EXPECT_EQ(Validate(m), nullptr);
  m.num_values = 14;
  EXPECT_STREQ(Validate(m), "num_values mismatch");
}

// A continuous batch: 3 floats per action (steer, gas, brake).
rlmsg::transition_batch_t ContinuousBatch() {
  rlmsg::transition_batch_t m = FlatBatch(2, 2, 3);
  m.action = {-0.5f, 1.0f, 0.0f, 0.25f, 0.0f, 0.75f};
  return m;
}

TEST(MessagesTest, ActionVectorsRoundTripAndBadActionsAreRefused) {
  const rlmsg::transition_batch_t m = ContinuousBatch();
  EXPECT_EQ(Validate(m), nullptr);
  const auto bytes = Encode(m);
  rlmsg::transition_batch_t back{};
  ASSERT_EQ(back.decode(bytes.data(), 0, static_cast<int>(bytes.size())),
            static_cast<int>(bytes.size()));
  EXPECT_EQ(back.action, m.action);
  EXPECT_EQ(back.action_width, 3);
  rlmsg::transition_batch_t bad = ContinuousBatch();
  bad.action[4] = std::nanf("");
  EXPECT_STREQ(Validate(bad), "non-finite action");
  bad = ContinuousBatch();
  bad.action[1] = std::numeric_limits<float>::infinity();
  EXPECT_STREQ(Validate(bad), "non-finite action");
  bad = ContinuousBatch();
  bad.num_action_values = 5;
  bad.action.pop_back();
  EXPECT_STREQ(Validate(bad), "num_action_values mismatch");
  bad = ContinuousBatch();
  bad.action_width = 0;
  bad.num_action_values = 0;
  bad.action.clear();
  EXPECT_STREQ(Validate(bad), "action_width outside [1, 64]");
  bad = ContinuousBatch();
  bad.action_width = 65;
  bad.num_action_values = 130;
  bad.action.assign(130, 0.0f);
  EXPECT_STREQ(Validate(bad), "action_width outside [1, 64]");
  // A forged action count: prescan refuses it before the decoder sizes a vector from it.
  auto forged = Encode(m);
  const std::vector<uint8_t> six = {0, 0, 0, 6};
  const auto at = std::search(forged.begin() + 40, forged.end(), six.begin(), six.end());
  ASSERT_NE(at, forged.end());
  *at = 0x7f;
  EXPECT_NE(Prescan(&m, forged.data(), forged.size()), nullptr);
}

TEST(ValidateTest, RefusesBatchesWithBothOrNeitherObservationKind) {
  rlmsg::transition_batch_t m = ContinuousBatch();
  m.stack = 2;
  m.height = m.width = 2;
  EXPECT_STREQ(Validate(m), "neither or both of flat and pixel observations");
  m = ContinuousBatch();
  m.obs_size = 0;
  EXPECT_STREQ(Validate(m), "neither or both of flat and pixel observations");
}

TEST(ValidateTest, AcceptsAWeightsChunk) {
  const rlmsg::weights_chunk_t m = examples::WeightsChunk("linear(4,2)", 10, 1, 0);
  EXPECT_EQ(Validate(m), nullptr);
}

// Two 2 x 3 frames (ids 7 and 8) and one transition of stack 2 naming them.
rlmsg::transition_batch_t PixelBatch() { return examples::PixelTransitions(7, 1, 2, 3); }

TEST(PrescanTest, RefusesAPixelBatchWithAForgedFrameLength) {
  rlmsg::transition_batch_t m = PixelBatch();
  auto bytes = Encode(m);
  // num_bytes sits after the header (sender "test"), actor_id, count, obs_size, num_values (and
  // no obs), height, width, stack, num_frames and two int64 frame ids.
  const size_t at = MacOffset(4) + kMacBytes + 16 + 12 + 4 + 16;
  ASSERT_EQ(bytes[at + 3], 12);  // the encoded num_bytes, big-endian
  bytes[at] = 0x7f;              // about 2^31 bytes claimed
  EXPECT_NE(Prescan(&m, bytes.data(), bytes.size()), nullptr);
}

TEST(ValidateTest, RefusesInconsistentPixelBatches) {
  rlmsg::transition_batch_t m = PixelBatch();
  EXPECT_EQ(Validate(m), nullptr);
  m.num_bytes = 11;
  m.frames.resize(11);
  EXPECT_STREQ(Validate(m), "num_bytes mismatch");
  m = PixelBatch();
  m.frame_id = {8, 7};
  EXPECT_STREQ(Validate(m), "frame ids not increasing");
  m = PixelBatch();
  m.num_refs = 3;
  m.obs_frames.push_back(7);
  m.next_obs_frames.push_back(7);
  EXPECT_STREQ(Validate(m), "num_refs mismatch");
  m = PixelBatch();
  m.stack = 0;
  EXPECT_STREQ(Validate(m), "bad frame geometry");
  m = PixelBatch();
  m.discount = {1.5f};
  EXPECT_STREQ(Validate(m), "discount outside [0, 1]");
}

TEST(ValidateTest, ChecksPixelSampleBatchesAndPriorityUpdates) {
  rlmsg::sample_batch_t m = examples::PixelSamples(2, 2, 2, 3);
  EXPECT_EQ(Validate(m), nullptr);
  m.num_bytes = 23;
  EXPECT_STREQ(Validate(m), "num_bytes mismatch");

  rlmsg::priority_update_t p{};
  p.header.sender = "learner";
  p.count = 2;
  p.index = {3, 9};
  p.priority = {0.5f, 2.0f};
  EXPECT_EQ(Validate(p), nullptr);
  p.priority[1] = std::nanf("");
  EXPECT_STREQ(Validate(p), "bad priority");
  p.priority[1] = 1.0f;
  p.index[0] = -1;
  EXPECT_STREQ(Validate(p), "negative index");
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
  rlmsg::transition_batch_t t = FlatBatch(2, 4, 1);
  t.reward[1] = std::numeric_limits<float>::infinity();
  EXPECT_STREQ(Validate(t), "non-finite value");
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
