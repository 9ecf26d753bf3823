#include "nn/gemv.h"

#include <algorithm>

#include "nn/kernels.h"
#include "nn/parallel.h"

namespace rl::nn::internal {

void Gemv(const float* w, int out, int in, const float* x, const float* b, bool relu, float* y) {
  // Each thread takes whole blocks of outputs, which it computes exactly as a single thread
  // would. The product is bound by reading the weight (one multiply-add per float loaded), so a
  // multiply-add counts as several of a matrix product's when deciding whether to split.
  constexpr int kBlockRows = 128;
  constexpr int kMemoryBoundFactor = 4;
  const KernelSet& kernels = Kernels();
  const int blocks = (out + kBlockRows - 1) / kBlockRows;
  const int tasks =
      out <= 16 ? 1 : TasksFor(static_cast<int64_t>(out) * in * kMemoryBoundFactor, blocks);
  ParallelFor(tasks, [&](int task) {
    const int i_begin = blocks * task / tasks * kBlockRows;
    const int i_end = std::min(out, blocks * (task + 1) / tasks * kBlockRows);
    kernels.gemv_rows(w, out, in, x, b, relu, y, i_begin, i_end);
  });
}

}  // namespace rl::nn::internal
