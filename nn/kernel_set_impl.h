// The KernelSet of one path's fp32 and copy kernels. Included by kernels_avx2.cc and
// kernels_avx512.cc after their kernels, outside the instruction-set region: it runs before
// anything has checked what the CPU can do.
#ifndef RL_NN_ISA
#error "nn/kernel_set_impl.h is included by the kernels_*.cc files only"
#endif

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
