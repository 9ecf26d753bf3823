// The avx512_bf16 path: the avx512 path's kernels, with the bf16 products on AVX512_BF16
// (nn/gemm_bf16_impl.h): 16-float vectors, panels of 48 rows, 48 x 8 results per micro-kernel.
// There is no AMX path: none of our machines with AMX could test one.
#include "nn/kernels_prelude.h"
#include "nn/kernels_target.h"

namespace rl::nn::internal::avx512 {
// The fp32 product of kernels_avx512.cc, for what the bf16 product hands back.
void GemmOne(const ConstView& a, const ConstView& b, const MutView& c, bool accumulate,
             const Epilogue& epilogue, Vector* workspace);
}  // namespace rl::nn::internal::avx512

// The kernels, compiled for this instruction set (the headers above are not: see
// nn/kernels_prelude.h).
RL_NN_TARGET_BEGIN(
    "avx2,fma,f16c,bmi,bmi2,lzcnt,movbe,avx512f,avx512bw,avx512dq,avx512vl,avx512cd,avx512bf16")
#define RL_NN_ISA avx512_bf16
#define RL_NN_AVX512 1
#include "nn/gemm_block_impl.h"
#include "nn/panel_gather_impl.h"
// (after the block helpers and the gather it uses)
#include "nn/gemm_bf16_impl.h"
RL_NN_TARGET_END

namespace rl::nn::internal {

// Built at the baseline: it runs before anything has checked what the CPU can do.
KernelSet Avx512Bf16Kernels() {
  KernelSet set = Avx512Kernels();
  set.name = "avx512_bf16";
  set.bf16_panel_rows = avx512_bf16::kMrB;
  set.bf16_nr = avx512_bf16::kNrB;
  set.gemm_bf16 = &avx512_bf16::GemmOneBf16;
  set.gemm_packed_bf16 = &avx512_bf16::GemmPackedOneBf16;
  set.gemm_pairs_bf16 = &avx512_bf16::GemmPairsOneBf16;
  set.im2col_pairs = &avx512_bf16::Im2colPairs;
  set.round_into_pairs = &avx512_bf16::RoundIntoPairs;
  return set;
}

}  // namespace rl::nn::internal
