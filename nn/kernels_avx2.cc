// The avx2 path: the kernels compiled for x86-64-v3 (AVX2, FMA, F16C, BMI), which every CPU the
// build supports runs. 8-float vectors, 16 registers. bf16 products are emulated (nn/gemm.cc).
#define RL_NN_ISA avx2
#define RL_NN_AVX512 0
#define RL_NN_TARGETS "avx2,fma,f16c,bmi,bmi2,lzcnt,movbe"
#include "nn/fp32_path_impl.h"

namespace rl::nn::internal {

KernelSet Avx2Kernels() { return avx2::Fp32KernelSet("avx2"); }

}  // namespace rl::nn::internal
