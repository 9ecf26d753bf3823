#include "nn/parallel.h"

#include <algorithm>
#include <atomic>
#include <condition_variable>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

namespace rl::nn {
namespace {

// Whether this thread is running a task of RunTasks(). A parallel section inside a task runs on
// that task's thread alone: the other threads are busy with the sibling tasks.
thread_local bool t_in_task = false;

// Marks the calling thread as running tasks for as long as it lives.
class InTask {
 public:
  InTask() : previous_(t_in_task) { t_in_task = true; }
  ~InTask() { t_in_task = previous_; }
  InTask(const InTask&) = delete;
  InTask& operator=(const InTask&) = delete;

 private:
  bool previous_;
};

// Worker threads that sleep on a condition variable until Run() hands out a call's tasks. Tasks
// are claimed one at a time, by the workers and by the caller once it has finished task 0: a
// worker that is slow to wake (the other cores busy with other programs) leaves its task to the
// caller instead of holding it up.
class Pool {
 public:
  explicit Pool(int workers) {
    threads_.reserve(static_cast<size_t>(workers));
    for (int w = 0; w < workers; ++w) threads_.emplace_back([this] { WorkerLoop(); });
  }

  ~Pool() {
    {
      std::lock_guard<std::mutex> lock(mu_);
      stop_ = true;
    }
    wake_.notify_all();
    for (std::thread& t : threads_) t.join();
  }

  Pool(const Pool&) = delete;
  Pool& operator=(const Pool&) = delete;

  void Run(int tasks, void (*fn)(void*, int), void* ctx) {
    {
      std::lock_guard<std::mutex> lock(mu_);
      fn_ = fn;
      ctx_ = ctx;
      tasks_ = tasks;
      next_task_ = 1;
      unfinished_ = tasks - 1;
      ++generation_;
    }
    wake_.notify_all();
    InTask in_task;
    fn(ctx, 0);
    std::unique_lock<std::mutex> lock(mu_);
    RunClaimedTasks(&lock);
    done_.wait(lock, [this] { return unfinished_ == 0; });
  }

 private:
  // Claims and runs the current call's tasks until none is left; `lock` holds mu_ on entry and
  // on return.
  void RunClaimedTasks(std::unique_lock<std::mutex>* lock) {
    while (next_task_ < tasks_) {
      const int task = next_task_++;
      void (*fn)(void*, int) = fn_;
      void* ctx = ctx_;
      lock->unlock();
      fn(ctx, task);
      lock->lock();
      if (--unfinished_ == 0) done_.notify_one();
    }
  }

  void WorkerLoop() {
    t_in_task = true;
    uint64_t seen = 0;
    std::unique_lock<std::mutex> lock(mu_);
    for (;;) {
      wake_.wait(lock, [&] { return stop_ || generation_ != seen; });
      if (stop_) return;
      seen = generation_;
      RunClaimedTasks(&lock);
    }
  }

  std::vector<std::thread> threads_;
  std::mutex mu_;
  std::condition_variable wake_;  // A new call (generation_ changed) or stop_.
  std::condition_variable done_;  // unfinished_ reached 0.
  // The current call, guarded by mu_.
  void (*fn_)(void*, int) = nullptr;
  void* ctx_ = nullptr;
  int tasks_ = 0;
  int next_task_ = 0;   // The next task nobody has claimed yet.
  int unfinished_ = 0;  // Tasks after task 0 that have not finished.
  uint64_t generation_ = 0;
  bool stop_ = false;
};

// Held while the pool runs a call (so that another application thread runs its tasks itself
// instead of waiting) and while SetNumThreads() replaces the pool. Declared before g_pool, so
// that the pool is destroyed (its workers joined) first at exit.
std::mutex g_pool_mu;
std::unique_ptr<Pool> g_pool;
std::atomic<int> g_threads{1};
std::atomic<int64_t> g_sections{0};

}  // namespace

void SetNumThreads(int n) {
  if (n < 1 || n > 64) {
    throw std::invalid_argument("SetNumThreads: need 1 to 64 threads, got " + std::to_string(n));
  }
  std::lock_guard<std::mutex> lock(g_pool_mu);
  if (n == g_threads.load()) return;
  g_pool.reset();
  if (n > 1) g_pool = std::make_unique<Pool>(n - 1);
  g_threads.store(n);
}

int NumThreads() { return g_threads.load(std::memory_order_relaxed); }

namespace internal {

int TasksFor(int64_t work, int64_t max_pieces) {
  const int threads = g_threads.load(std::memory_order_relaxed);
  if (threads == 1 || t_in_task) return 1;
  const int64_t pieces = std::min({int64_t{threads}, max_pieces, work / kMinTaskWork});
  return static_cast<int>(std::max<int64_t>(pieces, 1));
}

int TasksForElements(int64_t elements, int64_t max_pieces) {
  return TasksFor(elements * (kMinTaskWork / kMinTaskElements), max_pieces);
}

void RunTasks(int tasks, void (*fn)(void* ctx, int task), void* ctx) {
  if (tasks <= 0) return;
  // A nested section, or one while another thread uses the pool (or without a pool): the tasks
  // in order, here. The nesting check comes first: this thread may hold g_pool_mu already.
  std::unique_lock<std::mutex> lock;
  if (!t_in_task) lock = std::unique_lock<std::mutex>(g_pool_mu, std::try_to_lock);
  if (!lock.owns_lock() || g_pool == nullptr) {
    InTask in_task;
    for (int task = 0; task < tasks; ++task) fn(ctx, task);
    return;
  }
  if (tasks > 1) g_sections.fetch_add(1, std::memory_order_relaxed);
  g_pool->Run(tasks, fn, ctx);
}

int64_t ParallelSections() { return g_sections.load(std::memory_order_relaxed); }

}  // namespace internal
}  // namespace rl::nn
