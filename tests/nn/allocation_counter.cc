#include "tests/nn/allocation_counter.h"

#include <atomic>
#include <cstddef>

#if defined(__SANITIZE_ADDRESS__)
#define RL_NN_COUNT_ALLOCATIONS 0
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define RL_NN_COUNT_ALLOCATIONS 0
#endif
#endif
#if !defined(RL_NN_COUNT_ALLOCATIONS) && defined(__GLIBC__)
#define RL_NN_COUNT_ALLOCATIONS 1
#endif
#if !defined(RL_NN_COUNT_ALLOCATIONS)
#define RL_NN_COUNT_ALLOCATIONS 0
#endif

namespace {
std::atomic<int64_t> g_allocations{0};
}  // namespace

#if RL_NN_COUNT_ALLOCATIONS
// glibc's allocator entry points; the definitions below interpose on malloc & co for the whole
// test process (libstdc++'s operator new included) and forward to them.
extern "C" {
void* __libc_malloc(size_t size);
void* __libc_calloc(size_t n, size_t size);
void* __libc_realloc(void* p, size_t size);
void* __libc_memalign(size_t alignment, size_t size);

void* malloc(size_t size) noexcept {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  return __libc_malloc(size);
}
void* calloc(size_t n, size_t size) noexcept {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  return __libc_calloc(n, size);
}
void* realloc(void* p, size_t size) noexcept {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  return __libc_realloc(p, size);
}
void* aligned_alloc(size_t alignment, size_t size) noexcept {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  return __libc_memalign(alignment, size);
}
int posix_memalign(void** out, size_t alignment, size_t size) noexcept {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  void* p = __libc_memalign(alignment, size);
  if (p == nullptr) return 12;  // ENOMEM
  *out = p;
  return 0;
}
}  // extern "C"
#endif

namespace rl::nn::testing {

bool AllocationCountingAvailable() { return RL_NN_COUNT_ALLOCATIONS != 0; }

int64_t AllocationCount() { return g_allocations.load(std::memory_order_relaxed); }

}  // namespace rl::nn::testing
