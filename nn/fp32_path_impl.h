// One fp32 kernel path: the fp32 and copy kernels compiled for one instruction set, and the
// KernelSet of them. Included by kernels_avx2.cc and kernels_avx512.cc only, which first define
// RL_NN_ISA (the path's namespace), RL_NN_AVX512 (1: the AVX-512 register blocking and masked
// copies) and RL_NN_TARGETS (the instruction sets, as RL_NN_TARGET_BEGIN takes them). Not part of
// the public API.
#if !defined(RL_NN_ISA) || !defined(RL_NN_AVX512) || !defined(RL_NN_TARGETS)
#error "nn/fp32_path_impl.h is included by the kernels_*.cc files only"
#endif

#include "nn/kernels_prelude.h"
#include "nn/kernels_target.h"

// The kernels, compiled for this instruction set (the headers above are not: see
// nn/kernels_prelude.h).
RL_NN_TARGET_BEGIN(RL_NN_TARGETS)
#include "nn/gemm_block_impl.h"
// (after the block helpers it uses)
#if RL_NN_AVX512
#include "nn/panel_gather_impl.h"
#endif
#include "nn/conv_impl.h"
#include "nn/gemm_fp32_impl.h"
#include "nn/gemv_impl.h"
RL_NN_TARGET_END

// The KernelSet, outside the instruction-set region: it runs before anything has checked what
// the CPU can do.
namespace rl::nn::internal::RL_NN_ISA {

inline KernelSet Fp32KernelSet(const char* name) {
  KernelSet set{};
  set.name = name;
  set.panel_rows = kMaxMr;
  set.nr = kNr;
  set.gemm = &GemmOne;
  set.gemm_packed = &GemmPackedOne;
  set.gemv_rows = &GemvRows;
  set.add_row_sums = &AddRowSums;
  set.copy_runs = &CopyRuns;
  set.deinterleave = &Deinterleave;
  set.interleave = &Interleave;
  set.im2col = &Im2col;
  set.im2col_panels = &Im2colPanels;
  set.plane_gradient = &PlaneGradient;
  return set;
}

}  // namespace rl::nn::internal::RL_NN_ISA
