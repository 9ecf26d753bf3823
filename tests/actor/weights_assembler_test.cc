#include "actor/weights_assembler.h"

#include <algorithm>
#include <numeric>

#include <gtest/gtest.h>

#include "learner/weights_publisher.h"

namespace rl::actor {
namespace {

std::vector<float> Params(int n, float scale) {
  std::vector<float> p(static_cast<size_t>(n));
  for (int i = 0; i < n; ++i) p[static_cast<size_t>(i)] = scale * static_cast<float>(i % 97);
  return p;
}

TEST(WeightsAssemblerTest, ReassemblesChunksArrivingInAnyOrder) {
  const auto params = Params(25000, 0.5f);
  auto chunks = learner::MakeWeightChunks(7, "linear(4,2)", params, 12000);
  ASSERT_EQ(chunks.size(), 3U);
  std::reverse(chunks.begin(), chunks.end());
  WeightsAssembler a;
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
  WeightsAssembler a;
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
  WeightsAssembler a;
  auto chunks = learner::MakeWeightChunks(3, "x", Params(100, 1.0f), 12000);
  chunks[0].data[10] += 1.0f;
  EXPECT_FALSE(a.Add(chunks[0]));
  EXPECT_FALSE(a.Take().has_value());
  EXPECT_EQ(a.rejected(), 1);
  EXPECT_EQ(a.complete_version(), -1);
}

TEST(WeightsAssemblerTest, IgnoresDuplicateChunks) {
  WeightsAssembler a;
  auto chunks = learner::MakeWeightChunks(4, "x", Params(30000, 1.0f), 12000);
  a.Add(chunks[0]);
  a.Add(chunks[0]);
  a.Add(chunks[1]);
  EXPECT_FALSE(a.Take().has_value());
  EXPECT_TRUE(a.Add(chunks[2]));
}

}  // namespace
}  // namespace rl::actor
