// Intra-op parallelism: a small persistent pool of worker threads over which the convolutions
// and the large matrix products split their work (see nn/README.md, "Threads").
#pragma once

#include <cstdint>

namespace rl::nn {

/// How many threads, the calling one included, nn computations may use. 1 (the default) runs
/// everything on the calling thread and starts no thread. n > 1 starts n - 1 worker threads,
/// shared by the whole process; Conv2d, Pool2d, ReLU and the pixel conversions (nn/pixels.h) then
/// split their batch over them, and large matrix products (Gemm, the single-observation Gemv)
/// split their rows. Results equal the single-threaded ones bit for bit, except the parameter
/// gradients of Conv2d, which each thread sums over its share of the batch before they are added
/// in a fixed order: they differ by rounding, and are the same from run to run for a given n.
/// Call it while no nn computation runs (typically at start-up); it waits for a parallel section
/// that is under way. Throws std::invalid_argument unless 1 <= n <= 64.
void SetNumThreads(int n);
/// The current setting of SetNumThreads().
int NumThreads();

namespace internal {

/// Work (multiply-adds) below which a piece is not worth handing to another thread: about 4M
/// take 40-80 us on one core, and waking a sleeping worker on a virtual machine can take tens of
/// microseconds. The batches of training are split; the layers of a single observation (at most
/// about 3M multiply-adds each in the Nature network) are not.
constexpr int64_t kMinTaskWork = int64_t{1} << 22;

/// The number of pieces a computation of `work` multiply-adds that can be cut into at most
/// `max_pieces` pieces should be split into: 1 with a single thread, inside a task of
/// ParallelFor() (no nesting), or when the work is too small (kMinTaskWork per piece);
/// otherwise up to NumThreads().
int TasksFor(int64_t work, int64_t max_pieces);

/// Elements of a pass that streams through memory (a pixel conversion, a pooling, a ReLU: 0.15
/// to 1.7 ns each on one core of the development machine) below which a piece is not worth
/// handing to another thread: 64K take 10-110 us.
constexpr int64_t kMinTaskElements = int64_t{1} << 16;

/// TasksFor() for a pass over `elements` elements (kMinTaskElements per piece).
int TasksForElements(int64_t elements, int64_t max_pieces);

/// Runs fn(ctx, i) for every i in [0, tasks) and returns when all are done: task 0 on the calling
/// thread, the others on whichever of the pool's workers or the calling thread (once it is done
/// with task 0) claims them first; all on the calling thread, in order, when another thread is
/// using the pool. Tasks must not depend on each other or on the thread that runs them, except
/// through thread-local scratch space. Does not allocate.
void RunTasks(int tasks, void (*fn)(void* ctx, int task), void* ctx);

/// How many calls of RunTasks() with more than one task the pool has run so far, in the whole
/// process: tells a benchmark whether a computation used threads at all.
int64_t ParallelSections();

/// RunTasks() for a callable f(int task); f(0) directly when tasks <= 1.
template <class F>
void ParallelFor(int tasks, const F& f) {
  if (tasks <= 1) {
    f(0);
    return;
  }
  RunTasks(
      tasks, [](void* ctx, int task) { (*static_cast<const F*>(ctx))(task); },
      const_cast<void*>(static_cast<const void*>(&f)));
}

/// ParallelFor() over the columns (samples) of a pass over `elements` elements in all: f(begin,
/// end) for each of TasksForElements(elements, batch) consecutive ranges that together cover
/// [0, batch), the first range on the calling thread.
template <class F>
void ParallelForColumns(int64_t batch, int64_t elements, const F& f) {
  const int tasks = TasksForElements(elements, batch);
  ParallelFor(tasks, [&](int task) { f(batch * task / tasks, batch * (task + 1) / tasks); });
}

}  // namespace internal
}  // namespace rl::nn
