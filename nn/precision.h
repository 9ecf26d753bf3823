// The arithmetic of the matrix products, and the instruction-set path of the kernels that run
// them (see nn/README.md, "Kernels and precision").
#pragma once

#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

namespace rl::nn {

/// What the matrix products of a layer (Linear, Conv2d, Dueling) compute in.
///   kFp32: float32 throughout.
///   kBf16: both inputs of every product the kernel computes (weights, activations, gradients)
///          are rounded to bfloat16 (to nearest, ties to even), the products and their sums are
///          float32. Weights, their gradients, optimizer states, activations, losses and
///          normalisation stay float32, and so do small products: single observations (Gemv),
///          those Eigen computes (see PreferGemm() in nn/gemm.h), and those with at most 4
///          result rows or fewer than 16 rows and more columns than rows.
enum class Precision { kFp32, kBf16 };

/// "fp32" or "bf16".
const char* PrecisionName(Precision precision);
/// The inverse of PrecisionName(). Throws std::invalid_argument for anything else.
Precision ParsePrecision(const std::string& name);

/// The kernel path in use: "avx512_bf16" (AVX-512 kernels, bf16 products on the CPU's bf16
/// dot-product instruction), "avx512" (AVX-512 kernels, bf16 emulated) or "avx2" (x86-64-v3
/// kernels, bf16 emulated). Chosen once, at the first product, from the CPU's features (the
/// fastest path it can run) or from the environment variable RL_KERNELS (one of these names, or
/// "auto"). Throws std::runtime_error when RL_KERNELS names a path that is unknown or that this
/// CPU cannot run, saying which features it lacks.
std::string KernelPath();

/// Whether bf16 products run on the CPU's instructions on the current path. Without them
/// (paths avx512 and avx2) they are emulated: the inputs are rounded to bfloat16 in software and
/// multiplied by the fp32 kernels, which gives the same results up to the order of the sums but
/// is slower than fp32.
bool NativeBf16();

/// Every path, fastest first, and those this CPU can run.
std::vector<std::string> KernelPaths();
std::vector<std::string> RunnableKernelPaths();

/// Makes `name` the path in use (tests and benchmarks; "auto" picks the fastest). Throws
/// std::invalid_argument for an unknown path or one this CPU cannot run. Call it while no
/// computation runs.
void SetKernelPath(const std::string& name);

/// The CPU features the paths depend on, for logs and benchmarks, e.g.
/// "avx2 fma f16c avx512 avx512_bf16 (no amx_bf16)".
std::string CpuFeatureSummary();

/// x rounded to the nearest bfloat16 (ties to even) and widened back to float: the rounding of
/// the bf16 products (also what AVX512_BF16's conversions do). NaN stays NaN, infinities stay,
/// finite values beyond the largest bfloat16 become infinities, and values below the smallest
/// normal bfloat16 (about 1.2e-38) become zeros of their sign, as the instructions treat them.
inline float RoundToBf16(float x) {
  uint32_t bits = 0;
  std::memcpy(&bits, &x, sizeof(bits));
  const uint32_t exponent = bits & 0x7F800000U;
  if (exponent == 0x7F800000U) {
    // Infinity stays; NaN stays NaN (quiet, its payload truncated).
    if ((bits & 0x007FFFFFU) != 0) bits |= 0x00400000U;
  } else if (exponent == 0) {
    bits &= 0x80000000U;  // zero or denormal: a zero of its sign
  } else {
    bits += 0x7FFFU + ((bits >> 16) & 1U);  // to nearest, ties to even (may carry to infinity)
  }
  bits &= 0xFFFF0000U;
  float out = 0;
  std::memcpy(&out, &bits, sizeof(out));
  return out;
}

}  // namespace rl::nn
