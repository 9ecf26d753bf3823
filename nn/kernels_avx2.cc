// The avx2 path: the kernels compiled for x86-64-v3 (AVX2, FMA, F16C, BMI), which every CPU the
// build supports runs. 8-float vectors, 16 registers. bf16 products are emulated (nn/gemm.cc).
#include "nn/kernels_prelude.h"
#include "nn/kernels_target.h"

// The kernels, compiled for this instruction set (the headers above are not: see
// nn/kernels_prelude.h).
RL_NN_TARGET_BEGIN("avx2,fma,f16c,bmi,bmi2,lzcnt,movbe")
#define RL_NN_ISA avx2
#define RL_NN_AVX512 0
#include "nn/gemm_block_impl.h"
// (after the block helpers it uses)
#include "nn/conv_impl.h"
#include "nn/gemm_fp32_impl.h"
#include "nn/gemv_impl.h"
RL_NN_TARGET_END

#include "nn/kernel_set_impl.h"

namespace rl::nn::internal {

KernelSet Avx2Kernels() { return avx2::Fp32KernelSet("avx2"); }

}  // namespace rl::nn::internal
