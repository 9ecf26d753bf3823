// The avx512 path: the kernels compiled for AVX-512 (F, BW, DQ, VL, CD; x86-64-v4): 32 registers,
// 16-float vectors, masked loads and stores in the copies. bf16 products are emulated
// (nn/gemm.cc).
#define RL_NN_ISA avx512
#define RL_NN_AVX512 1
#define RL_NN_TARGETS \
  "avx2,fma,f16c,bmi,bmi2,lzcnt,movbe,avx512f,avx512bw,avx512dq,avx512vl,avx512cd"
#include "nn/fp32_path_impl.h"

namespace rl::nn::internal {

KernelSet Avx512Kernels() { return avx512::Fp32KernelSet("avx512"); }

}  // namespace rl::nn::internal
