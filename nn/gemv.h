// Internal matrix-vector kernel for single-observation inference (the actors' and the
// evaluator's hot path). Not part of the public API.
//
// Eigen's matrix-vector product takes about 0.5 us for the 84x120 layer of the DQN MLP; keeping
// up to 128 outputs in AVX-512 registers while walking the columns of the column-major weight
// (one broadcast and one fused multiply-add per 16 outputs and column) takes about a quarter of
// that. Narrow layers (one register of outputs) split the columns over four independent chains
// so that the multiply-add latency does not serialise them. On the avx2 path (nn/kernels.h) the
// same column walk is left to the compiler's vectorisation. Always fp32.
#pragma once

namespace rl::nn::internal {

/// y = w x + b for a column-major `out` x `in` matrix w, then max(y, 0) when `relu`.
/// `y` must not overlap the inputs. O(out in), no allocation. With SetNumThreads(n > 1)
/// (nn/parallel.h) a large product splits its outputs, in blocks of 128, over the threads, with
/// the same result bit for bit.
void Gemv(const float* w, int out, int in, const float* x, const float* b, bool relu, float* y);

}  // namespace rl::nn::internal
