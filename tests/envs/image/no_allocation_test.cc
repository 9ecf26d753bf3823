// Checks that the pixel pipeline's Step and Reset do not allocate after the first Reset. This file
// replaces the global operator new and delete of the whole test program with versions that count
// the allocations (and otherwise behave as the standard ones), so it sees every C++ allocation,
// ours and the standard library's; allocations inside OpenCV go through malloc and are not seen
// (see pixel_env.h for the one known case, which this test avoids by resizing by an integer
// ratio). Under AddressSanitizer, which brings its own operator new, the counting is left out and
// the test skips.
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <memory>
#include <new>
#include <span>

#include <gtest/gtest.h>

#include "envs/image/pixel_env.h"
#include "envs/registry.h"

#if defined(__SANITIZE_ADDRESS__)
#define RL_COUNT_ALLOCATIONS 0
#else
#define RL_COUNT_ALLOCATIONS 1
#endif

namespace {
std::atomic<int64_t> g_allocations{0};
}  // namespace

#if RL_COUNT_ALLOCATIONS
// The other forms of new and delete (arrays, nothrow, sized) call these in libstdc++.
void* operator new(std::size_t size) {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  if (void* p = std::malloc(size == 0 ? 1 : size)) return p;
  throw std::bad_alloc();
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t /*size*/) noexcept { std::free(p); }
#endif

namespace rl::envs {
namespace {

TEST(PixelEnvAllocationTest, StepAndResetDoNotAllocateAfterTheFirstReset) {
  if (!RL_COUNT_ALLOCATIONS) GTEST_SKIP() << "allocation counting is off under AddressSanitizer";

  // Catch at 40x80 resized to 20x40 (an integer ratio), with every stage switched on.
  ImagePipelineConfig config;
  config.width = 20;
  config.height = 40;
  config.frame_skip = 2;
  config.max_pool = true;
  config.stack = 4;
  config.clip_rewards = true;
  auto env = MakePixelEnv(MakeEnv("Catch-v0"), config);
  env->Reset(1);
  const float* observation = env->observation().data();
  const uint8_t* frame = env->frame().data();

  // Play 200 episodes; count allocations without calling into GoogleTest meanwhile. The resets
  // are unseeded, as an actor's are after its first: a seeded Reset allocates in std::seed_seq
  // (SeedRng in envs/rng.cc), whatever the env.
  const int64_t before = g_allocations.load();
  bool buffers_stable = true;
  int episodes = 0;
  while (episodes < 200) {
    const StepResult r = env->Step(DiscreteAction(episodes % 3));
    buffers_stable =
        buffers_stable && env->observation().data() == observation && env->frame().data() == frame;
    if (r.terminated || r.truncated) {
      ++episodes;
      env->Reset();
    }
  }
  const int64_t allocations = g_allocations.load() - before;
  EXPECT_EQ(allocations, 0);
  EXPECT_TRUE(buffers_stable);
}

}  // namespace
}  // namespace rl::envs
