#include "learner/batch_decoder.h"

#include <random>
#include <stdexcept>
#include <vector>

#include <gtest/gtest.h>

#include "envs/specs.h"

namespace rl::learner {
namespace {

// A spec of 2 x 3 x 3 pixel stacks (the decoder needs only the geometry and the action width).
envs::EnvSpec PixelSpec() {
  envs::EnvSpec spec = envs::CatchSpec();
  spec.frame_stack = 2;
  spec.frame_height = 3;
  spec.frame_width = 3;
  spec.observation_size = 18;
  return spec;
}

// A reply of n pixel stacks: flat frames (every pixel of a stack alike) when `flat`.
rlmsg::sample_batch_t PixelReply(int n, bool flat, std::mt19937* rng) {
  std::uniform_int_distribution<int> byte(0, 255);
  rlmsg::sample_batch_t m{};
  m.count = n;
  m.height = m.width = 3;
  m.stack = 2;
  m.num_bytes = 18 * n;
  for (int i = 0; i < n; ++i) {
    for (std::vector<uint8_t>* v : {&m.obs_pixels, &m.next_obs_pixels}) {
      const int level = byte(*rng);
      for (int k = 0; k < 18; ++k) v->push_back(static_cast<uint8_t>(flat ? level : byte(*rng)));
    }
    m.action.push_back(static_cast<float>(i % 3));
    m.reward.push_back(0.5f);
    m.discount.push_back(0.9f);
    m.weight.push_back(1.0f);
  }
  m.action_width = 1;
  m.num_action_values = n;
  return m;
}

TEST(BatchDecoderTest, FlatRepliesAreCopiedAndPixelsDividedBy255) {
  BatchDecoder flat(envs::PendulumSpec(), 0, 1);
  rlmsg::sample_batch_t m{};
  m.count = 2;
  m.obs_size = 3;
  m.num_values = 6;
  m.obs = {1, 2, 3, 4, 5, 6};
  m.next_obs = {7, 8, 9, 10, 11, 12};
  m.action_width = 1;
  m.num_action_values = 2;
  m.action = {-1.5f, 0.25f};
  m.reward = {1, 2};
  m.discount = {0.9f, 0};
  m.weight = {1, 0.5f};
  Batch b;
  ASSERT_EQ(flat.Decode(m, &b), nullptr);
  EXPECT_EQ(b.count, 2);
  EXPECT_EQ(b.action_width, 1);
  EXPECT_EQ((*b.obs)(2, 1), 6.0f);  // transition 1, value 2
  EXPECT_EQ((*b.next_obs)(0, 1), 10.0f);
  EXPECT_EQ(b.action[0], -1.5f);
  EXPECT_EQ(b.weight[1], 0.5f);

  BatchDecoder pixels(PixelSpec(), 0, 1);
  std::mt19937 rng(2);
  const rlmsg::sample_batch_t p = PixelReply(4, false, &rng);
  ASSERT_EQ(pixels.Decode(p, &b), nullptr);
  for (int i = 0; i < 4; ++i) {
    for (int k = 0; k < 18; ++k) {
      EXPECT_EQ((*b.obs)(k, i),
                static_cast<float>(p.obs_pixels[static_cast<size_t>(18 * i + k)]) / 255.0f);
    }
  }
}

TEST(BatchDecoderTest, RefusesRepliesThatDoNotFitTheEnv) {
  std::mt19937 rng(3);
  BatchDecoder pixels(PixelSpec(), 0, 1);
  Batch b;
  rlmsg::sample_batch_t p = PixelReply(4, false, &rng);
  p.height = 2;
  EXPECT_STREQ(pixels.Decode(p, &b), "pixel geometry differs from the env's");
  p = PixelReply(4, false, &rng);
  p.action_width = 3;
  EXPECT_STREQ(pixels.Decode(p, &b), "action width differs from the env's");
  BatchDecoder flat(envs::PendulumSpec(), 0, 1);
  const rlmsg::sample_batch_t m = PixelReply(4, false, &rng);  // pixels for a flat env
  EXPECT_STREQ(flat.Decode(m, &b), "observation size differs from the env's");
  EXPECT_THROW(BatchDecoder(envs::PendulumSpec(), 2, 1), std::invalid_argument);
  EXPECT_THROW(BatchDecoder(PixelSpec(), -1, 1), std::invalid_argument);
}

// Decodes a reply with the given shift and returns the observations as floats.
std::vector<float> Decoded(int shift, const rlmsg::sample_batch_t& m, uint64_t seed) {
  BatchDecoder d(PixelSpec(), shift, seed);
  Batch b;
  EXPECT_EQ(d.Decode(m, &b), nullptr);
  return std::vector<float>(b.obs->data(), b.obs->data() + b.obs->size());
}

TEST(BatchDecoderTest, RandomShiftsMoveThePixelsAndNothingElse) {
  std::mt19937 rng(9);
  // A shift leaves a flat frame as it is (the edges repeat), so the inputs are the same.
  const rlmsg::sample_batch_t flat = PixelReply(8, true, &rng);
  EXPECT_EQ(Decoded(1, flat, 5), Decoded(0, flat, 5));
  // On random frames the shifts change what the network sees, the same way for the same seed.
  const rlmsg::sample_batch_t noise = PixelReply(8, false, &rng);
  EXPECT_NE(Decoded(1, noise, 5), Decoded(0, noise, 5));
  EXPECT_EQ(Decoded(1, noise, 5), Decoded(1, noise, 5));
  EXPECT_NE(Decoded(1, noise, 5), Decoded(1, noise, 6));
}

}  // namespace
}  // namespace rl::learner
