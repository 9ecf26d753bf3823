// HugePageAllocator: an allocator for the replay's large arrays (the frame ring) that asks the
// kernel to back them with transparent huge pages (2 MiB) when it offers them on request
// (/sys/kernel/mm/transparent_hugepage/enabled "madvise" or "always"). fork() copies a process's
// page tables: a 1 GB frame ring in 4 KiB pages is 262,144 entries, in huge pages 512, so the
// snapshot's fork pauses the daemon far less (replay/README.md, Snapshots). The ring is written
// in order, so a copy-on-write fault during a snapshot copies 2 MiB that the next frames would
// have dirtied anyway. Arrays under 2 MiB, and kernels without huge pages, get ordinary memory.
#pragma once

#include <sys/mman.h>

#include <cstddef>
#include <cstdlib>
#include <memory>
#include <new>

namespace rl::replay {

template <class T>
struct HugePageAllocator {
  using value_type = T;
  static constexpr size_t kHugePage = size_t{2} << 20;

  HugePageAllocator() = default;
  template <class U>
  explicit HugePageAllocator(const HugePageAllocator<U>& /*other*/) {}

  /// Large arrays: 2 MiB-aligned, rounded up to whole huge pages, advised MADV_HUGEPAGE before
  /// they are touched. Throws std::bad_alloc.
  T* allocate(size_t n) {
    const size_t bytes = n * sizeof(T);
    if (bytes < kHugePage) return std::allocator<T>().allocate(n);
    const size_t rounded = (bytes + kHugePage - 1) / kHugePage * kHugePage;
    void* p = nullptr;
    if (posix_memalign(&p, kHugePage, rounded) != 0) throw std::bad_alloc();
    madvise(p, rounded, MADV_HUGEPAGE);  // advice only: ignored where unsupported
    return static_cast<T*>(p);
  }
  void deallocate(T* p, size_t n) {
    if (n * sizeof(T) < kHugePage) {
      std::allocator<T>().deallocate(p, n);
    } else {
      free(p);
    }
  }
  template <class U>
  bool operator==(const HugePageAllocator<U>& /*other*/) const {
    return true;
  }
};

}  // namespace rl::replay
