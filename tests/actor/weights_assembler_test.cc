#include "actor/weights_assembler.h"

#include <algorithm>
#include <cstdint>
#include <limits>
#include <numeric>
#include <string>

#include <gtest/gtest.h>

#include "learner/weights_publisher.h"

namespace rl::actor {
namespace {

std::vector<float> Params(int n, float scale) {
  std::vector<float> p(static_cast<size_t>(n));
  for (int i = 0; i < n; ++i) p[static_cast<size_t>(i)] = scale * static_cast<float>(i % 97);
  return p;
}

// A receiver that expects networks of `floats` parameters whatever their architecture (the
// assembler only passes the string on), and counts how often it is asked.
WeightsAssembler::SizeOf Expect(int64_t floats, int* asked = nullptr) {
  return [floats, asked](const std::string&) {
    if (asked != nullptr) ++*asked;
    return floats;
  };
}

TEST(WeightsAssemblerTest, ReassemblesChunksArrivingInAnyOrder) {
  const auto params = Params(25000, 0.5f);
  auto chunks = learner::MakeWeightChunks(7, "linear(4,2)", params, 12000);
  ASSERT_EQ(chunks.size(), 3U);
  std::reverse(chunks.begin(), chunks.end());
  WeightsAssembler a(Expect(25000));
  EXPECT_FALSE(a.Add(chunks[0]));
  EXPECT_FALSE(a.Take().has_value());
  EXPECT_FALSE(a.Add(chunks[1]));
  EXPECT_TRUE(a.Add(chunks[2]));
  auto w = a.Take();
  ASSERT_TRUE(w.has_value());
  EXPECT_EQ(w->version, 7);
  EXPECT_EQ(w->architecture, "linear(4,2)");
  EXPECT_EQ(w->params, params);
  EXPECT_FALSE(a.Take().has_value());
}

TEST(WeightsAssemblerTest, AMissingChunkCostsTheVersionButNotTheNext) {
  WeightsAssembler a(Expect(30000));
  auto v1 = learner::MakeWeightChunks(1, "x", Params(30000, 1.0f), 12000);
  auto v2 = learner::MakeWeightChunks(2, "x", Params(30000, 2.0f), 12000);
  a.Add(v1[0]);
  a.Add(v1[2]);  // v1[1] lost
  for (auto& c : v2) a.Add(c);
  auto w = a.Take();
  ASSERT_TRUE(w.has_value());
  EXPECT_EQ(w->version, 2);
  // The late chunk of the older version changes nothing.
  EXPECT_FALSE(a.Add(v1[1]));
  EXPECT_EQ(a.complete_version(), 2);
}

TEST(WeightsAssemblerTest, RefusesAVersionWhoseChecksumDoesNotMatch) {
  WeightsAssembler a(Expect(100));
  auto chunks = learner::MakeWeightChunks(3, "x", Params(100, 1.0f), 12000);
  chunks[0].data[10] += 1.0f;
  EXPECT_FALSE(a.Add(chunks[0]));
  EXPECT_FALSE(a.Take().has_value());
  EXPECT_EQ(a.rejected(), 1);
  EXPECT_EQ(a.complete_version(), -1);
}

TEST(WeightsAssemblerTest, IgnoresDuplicateChunks) {
  WeightsAssembler a(Expect(30000));
  auto chunks = learner::MakeWeightChunks(4, "x", Params(30000, 1.0f), 12000);
  a.Add(chunks[0]);
  a.Add(chunks[0]);
  a.Add(chunks[1]);
  EXPECT_FALSE(a.Take().has_value());
  EXPECT_TRUE(a.Add(chunks[2]));
}

// The size of what a version may allocate is the receiver's network's, not the message's: a
// chunk claiming another total size, an architecture the receiver refuses, or more chunks than
// floats is refused at once (counted once per version), and a good version still completes.
TEST(WeightsAssemblerTest, RefusesVersionsOfAnotherSizeBeforeAllocating) {
  int asked = 0;
  WeightsAssembler a(Expect(100, &asked));
  const auto params = Params(100, 1.0f);
  rlmsg::weights_chunk_t huge = learner::MakeWeightChunks(1, "x", params, 40)[0];
  huge.total_size = std::numeric_limits<int32_t>::max();  // 8 GB of floats
  EXPECT_FALSE(a.Add(huge));
  EXPECT_FALSE(a.Add(huge));  // the same version again: refused, not counted again
  EXPECT_EQ(a.refused(), 1);
  rlmsg::weights_chunk_t many = learner::MakeWeightChunks(2, "x", params, 40)[0];
  many.num_chunks = std::numeric_limits<int32_t>::max();  // 2^31 chunks of 100 floats
  EXPECT_FALSE(a.Add(many));
  EXPECT_EQ(a.refused(), 2);
  EXPECT_EQ(asked, 1) << "one answer per architecture in a row";
  for (const auto& c : learner::MakeWeightChunks(3, "x", params, 40)) a.Add(c);
  const auto w = a.Take();
  ASSERT_TRUE(w.has_value());
  EXPECT_EQ(w->version, 3);
  EXPECT_EQ(w->params, params);
  // An architecture the receiver refuses (a negative size) is refused at its first chunk.
  WeightsAssembler none([](const std::string&) { return int64_t{-1}; });
  EXPECT_FALSE(none.Add(learner::MakeWeightChunks(4, "y", params, 200)[0]));
  EXPECT_EQ(none.refused(), 1);
  EXPECT_EQ(none.complete_version(), -1);
}

}  // namespace
}  // namespace rl::actor
