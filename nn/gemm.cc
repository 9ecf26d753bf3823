#include "nn/gemm.h"

#include <algorithm>
#include <vector>

#include "common/check.h"
#include "nn/kernels.h"
#include "nn/parallel.h"

namespace rl::nn::internal {
namespace {

// Rows [i0, i0 + rows) of a, columns [j0, j0 + cols) of b, and that block of c.
ConstView Rows(const ConstView& a, int i0, int rows) {
  return {a.data + i0 * a.row_stride, rows, a.cols, a.row_stride, a.col_stride};
}
ConstView Cols(const ConstView& b, int j0, int cols) {
  return {b.data + j0 * b.col_stride, b.rows, cols, b.row_stride, b.col_stride};
}
MutView Part(const MutView& c, int i0, int rows, int j0, int cols) {
  return {c.data + i0 * c.row_stride + j0 * c.col_stride, rows, cols, c.row_stride, c.col_stride};
}
// The epilogue of the block of c that starts at (i0, j0).
Epilogue ShiftEpilogue(Epilogue e, const MutView& c, int i0, int j0) {
  if (e.row_bias != nullptr) e.row_bias += i0;
  if (e.col_bias != nullptr) e.col_bias += j0;
  if (e.mask != nullptr) e.mask += i0 * c.row_stride + j0 * c.col_stride;
  return e;
}

// Scratch space of the tasks that do not run with the caller's workspace, one per task index and
// owned by the calling thread: whichever thread of the pool runs task t, it uses buffer t, so once
// a product of a shape has run, the next one of that shape allocates nothing however the threads
// share the tasks (buffers per running thread would grow again whenever a thread first ran a
// task of a larger block).
std::vector<GemmWorkspace>* CallerTaskWorkspaces() {
  thread_local std::vector<GemmWorkspace> workspaces;
  return &workspaces;
}

// The kernel that computes a product in `precision`: its functions and its blocking.
struct Product {
  GemmFn gemm;
  GemmPackedFn gemm_packed;
  int panel_rows;
  int nr;
};

Product ProductFor(const KernelSet& set, Precision precision) {
  if (precision == Precision::kBf16 && set.gemm_bf16 != nullptr) {
    return {set.gemm_bf16, set.gemm_packed_bf16, set.bf16_panel_rows, set.bf16_nr};
  }
  return {set.gemm, set.gemm_packed, set.panel_rows, set.nr};
}

// Splits an m x n result (at least one panel of rows) of `work` multiply-adds over the threads
// and calls piece(i0, rows, j0, cols, workspace) for each block: by whole panels of rows when
// there are at least two full ones (every block then holds a full panel, the last one also the
// ragged rest), otherwise by blocks of nr columns. Every block then takes the kernel with the
// same panels and the same order of operations per element as the whole product, so the results
// do not depend on the split. A single piece runs directly with `workspace`.
template <class F>
void SplitResult(const Product& kernel, int m, int n, int64_t work, GemmWorkspace* workspace,
                 const F& piece) {
  const int full_panels = m / kernel.panel_rows;
  const bool by_rows = full_panels >= 2;
  const int units = by_rows ? full_panels : n / kernel.nr;
  const int tasks = TasksFor(work, units);
  if (tasks <= 1) return piece(0, m, 0, n, &workspace->kernel);
  std::vector<GemmWorkspace>* task_workspaces = CallerTaskWorkspaces();
  if (static_cast<int>(task_workspaces->size()) < tasks) task_workspaces->resize(tasks);
  ParallelFor(tasks, [&](int task) {
    const int u0 = units * task / tasks;
    const int u1 = units * (task + 1) / tasks;
    const bool last = task == tasks - 1;
    Vector* ws = task == 0 ? &workspace->kernel : &(*task_workspaces)[task].kernel;
    if (by_rows) {
      const int i0 = u0 * kernel.panel_rows;
      piece(i0, (last ? m : u1 * kernel.panel_rows) - i0, 0, n, ws);
    } else {
      const int j0 = u0 * kernel.nr;
      piece(0, m, j0, (last ? n : u1 * kernel.nr) - j0, ws);
    }
  });
}

// bf16 without the CPU's instructions: copies of the operands rounded to bfloat16, which the
// fp32 kernels then multiply. Each copy is column-major, in the workspace's rounded_a and
// rounded_b (not in buffers of the running thread: which thread of the pool runs a task varies,
// and a thread that first met a larger product after the others would allocate).
ConstView RoundedCopy(const ConstView& v, Vector* buffer) {
  const int64_t size = static_cast<int64_t>(v.rows) * v.cols;
  if (buffer->size() < size) buffer->resize(size);
  float* out = buffer->data();
  for (int j = 0; j < v.cols; ++j) {
    const float* col = v.data + j * v.col_stride;
    for (int i = 0; i < v.rows; ++i)
      out[i + static_cast<int64_t>(j) * v.rows] = RoundToBf16(col[i * v.row_stride]);
  }
  return {out, v.rows, v.cols, 1, v.rows};
}

// Whether a product in bf16 has its inputs rounded (nn/precision.h): not those without a shared
// dimension, with at most 4 rows and contiguous columns of B (dot products), or with fewer rows
// than 16 and more columns than rows; the kernels compute those in fp32.
bool Bf16Applies(const ConstView& a, const ConstView& b, const MutView& c) {
  const int m = c.rows;
  const int n = c.cols;
  return a.cols > 0 && !(m <= 4 && b.row_stride == 1) && !(m < 16 && n > m);
}

}  // namespace

bool PreferGemm(int m, int n, int k) {
  constexpr int kLanes = 8;
  return n >= 2 && (m >= kLanes || n >= kLanes) && static_cast<int64_t>(m) * n * k >= 8192;
}

int PackedPanelRows(Precision precision) { return ProductFor(Kernels(), precision).panel_rows; }

void Gemm(ConstView a, ConstView b, MutView c, bool accumulate, const Epilogue& epilogue,
          GemmWorkspace* workspace, Precision precision) {
  RL_CHECK(a.cols == b.rows && a.rows == c.rows && b.cols == c.cols)
      << "Gemm shapes: (" << a.rows << "x" << a.cols << ") * (" << b.rows << "x" << b.cols
      << ") -> (" << c.rows << "x" << c.cols << ")";
  const KernelSet& set = Kernels();
  if (precision == Precision::kBf16 && !Bf16Applies(a, b, c)) precision = Precision::kFp32;
  if (precision == Precision::kBf16 && set.gemm_bf16 == nullptr) {
    return Gemm(RoundedCopy(a, &workspace->rounded_a), RoundedCopy(b, &workspace->rounded_b), c,
                accumulate, epilogue, workspace, Precision::kFp32);
  }
  const Product kernel = ProductFor(set, precision);
  const int m = c.rows;
  const int n = c.cols;
  const int k = a.cols;
  // Products with fewer rows than a panel take other paths than the panels; they are not split.
  if (m < kernel.panel_rows || n == 0 || k == 0) {
    return kernel.gemm(a, b, c, accumulate, epilogue, &workspace->kernel);
  }
  SplitResult(kernel, m, n, static_cast<int64_t>(m) * n * k, workspace,
              [&](int i0, int rows, int j0, int cols, Vector* ws) {
                kernel.gemm(Rows(a, i0, rows), Cols(b, j0, cols), Part(c, i0, rows, j0, cols),
                            accumulate, ShiftEpilogue(epilogue, c, i0, j0), ws);
              });
}

void GemmPacked(const float* a_packed, int m, int k, ConstView b, MutView c, bool accumulate,
                const Epilogue& epilogue, GemmWorkspace* workspace, Precision precision) {
  RL_CHECK(k == b.rows && m == c.rows && b.cols == c.cols)
      << "GemmPacked shapes: (" << m << "x" << k << ") * (" << b.rows << "x" << b.cols << ") -> ("
      << c.rows << "x" << c.cols << ")";
  const KernelSet& set = Kernels();
  const int n = c.cols;
  if (m == 0 || n == 0) return;
  const Product kernel = ProductFor(set, precision);
  const int rows_per_panel = kernel.panel_rows;
  if (k == 0) {
    return Gemm({a_packed, m, 0, 1, m}, b, c, accumulate, epilogue, workspace, precision);
  }
  if (precision == Precision::kBf16 && set.gemm_bf16 == nullptr) {
    // The packed operand rounded whole (its padding rows too), then the fp32 kernel.
    Vector& rounded_a = workspace->rounded_a;
    const int64_t size =
        static_cast<int64_t>((m + rows_per_panel - 1) / rows_per_panel) * rows_per_panel * k;
    if (rounded_a.size() < size) rounded_a.resize(size);
    std::transform(a_packed, a_packed + size, rounded_a.data(), RoundToBf16);
    return GemmPacked(rounded_a.data(), m, k, RoundedCopy(b, &workspace->rounded_b), c, accumulate,
                      epilogue, workspace, Precision::kFp32);
  }
  if (m < rows_per_panel) {
    return kernel.gemm_packed(a_packed, m, k, b, c, accumulate, epilogue, &workspace->kernel);
  }
  // A block of rows starting at i0 (a whole number of panels) starts at panel i0 / R.
  SplitResult(kernel, m, n, static_cast<int64_t>(m) * n * k, workspace,
              [&](int i0, int rows, int j0, int cols, Vector* ws) {
                kernel.gemm_packed(a_packed + static_cast<int64_t>(i0) * k, rows, k,
                                   Cols(b, j0, cols), Part(c, i0, rows, j0, cols), accumulate,
                                   ShiftEpilogue(epilogue, c, i0, j0), ws);
              });
}

int64_t PackedPairs(int m, int k) {
  const int rows = PackedPanelRows(Precision::kBf16);
  return static_cast<int64_t>((m + rows - 1) / rows) * rows * ((k + 1) / 2);
}

void GemmPackedPairs(const uint32_t* a_pairs, int m, int k, ConstView b, MutView c, bool accumulate,
                     const Epilogue& epilogue, GemmWorkspace* workspace) {
  RL_CHECK(k == b.rows && m == c.rows && b.cols == c.cols && k > 0)
      << "GemmPackedPairs shapes: (" << m << "x" << k << ") * (" << b.rows << "x" << b.cols
      << ") -> (" << c.rows << "x" << c.cols << ")";
  const KernelSet& set = Kernels();
  RL_CHECK(set.gemm_pairs_bf16 != nullptr) << "GemmPackedPairs on the " << set.name << " path";
  const int n = c.cols;
  if (m == 0 || n == 0) return;
  const Product kernel = ProductFor(set, Precision::kBf16);
  const int64_t pairs_per_row = (k + 1) / 2;
  SplitResult(kernel, m, n, static_cast<int64_t>(m) * n * k, workspace,
              [&](int i0, int rows, int j0, int cols, Vector* ws) {
                set.gemm_pairs_bf16(a_pairs + i0 * pairs_per_row, rows, k, Cols(b, j0, cols),
                                    Part(c, i0, rows, j0, cols), accumulate,
                                    ShiftEpilogue(epilogue, c, i0, j0), ws);
              });
}

void RoundIntoPairs(ConstView a, uint32_t* pairs) {
  const KernelSet& set = Kernels();
  RL_CHECK(set.round_into_pairs != nullptr) << "RoundIntoPairs on the " << set.name << " path";
  const int rows_per_panel = set.bf16_panel_rows;
  const int panels = (a.rows + rows_per_panel - 1) / rows_per_panel;
  const int64_t pairs_per_row = (a.cols + 1) / 2;
  const int tasks = TasksForElements(static_cast<int64_t>(a.rows) * a.cols, panels);
  ParallelFor(tasks, [&](int task) {
    const int i0 = panels * task / tasks * rows_per_panel;
    const int i1 = std::min(a.rows, panels * (task + 1) / tasks * rows_per_panel);
    set.round_into_pairs(a, i0, i1 - i0, pairs + i0 * pairs_per_row);
  });
}

bool GemmUsesPairs(ConstView a, ConstView b, MutView c) {
  return Kernels().gemm_bf16 != nullptr && Bf16Applies(a, b, c);
}

void AddRowSums(const Matrix& g, float* out) {
  Kernels().add_row_sums(g.data(), static_cast<int>(g.rows()), static_cast<int>(g.cols()), out);
}

}  // namespace rl::nn::internal
