// The avx512 path: the kernels compiled for AVX-512 (F, BW, DQ, VL, CD; x86-64-v4): 32 registers,
// 16-float vectors, masked loads and stores in the copies. bf16 products are emulated
// (nn/gemm.cc).
#include "nn/kernels_prelude.h"
#include "nn/kernels_target.h"

// The kernels, compiled for this instruction set (the headers above are not: see
// nn/kernels_prelude.h).
RL_NN_TARGET_BEGIN("avx2,fma,f16c,bmi,bmi2,lzcnt,movbe,avx512f,avx512bw,avx512dq,avx512vl,avx512cd")
#define RL_NN_ISA avx512
#define RL_NN_AVX512 1
#include "nn/gemm_block_impl.h"
// (after the block helpers it uses)
#include "nn/conv_impl.h"
#include "nn/gemm_fp32_impl.h"
#include "nn/gemv_impl.h"
RL_NN_TARGET_END

#include "nn/kernel_set_impl.h"

namespace rl::nn::internal {

KernelSet Avx512Kernels() { return avx512::Fp32KernelSet("avx512"); }

}  // namespace rl::nn::internal
