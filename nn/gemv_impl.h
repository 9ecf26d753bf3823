// The single-observation matrix-vector kernel of one path (see nn/gemv.h). Included by the
// kernels_*.cc files only, inside the namespace of their instruction set (RL_NN_ISA).
#ifndef RL_NN_ISA
#error "nn/gemv_impl.h is included by the kernels_*.cc files only"
#endif

namespace rl::nn::internal::RL_NN_ISA {
namespace {

// Outputs per block: at most 8 AVX-512 registers of accumulators.
constexpr int kBlockRows = 128;

#if RL_NN_AVX512
// Outputs [i0, i0 + 16 * NV) (the last register masked by `tail`), all columns in one pass. The
// accumulators are named variables, not an array, so that GCC keeps them in registers.
template <int NV>
void GemvBlock(const float* w, int out, int in, const float* x, const float* b, bool relu, float* y,
               int i0, __mmask16 tail) {
  static_assert(NV >= 1 && NV <= 8);
  auto mask = [tail](int v) { return v == NV - 1 ? tail : static_cast<__mmask16>(0xFFFF); };
  auto load = [&mask](const float* p, int v) { return _mm512_maskz_loadu_ps(mask(v), p + 16 * v); };
  const __m512 zero = _mm512_setzero_ps();
  __m512 a0 = load(b + i0, 0);
  __m512 a1 = NV > 1 ? load(b + i0, 1) : zero;
  __m512 a2 = NV > 2 ? load(b + i0, 2) : zero;
  __m512 a3 = NV > 3 ? load(b + i0, 3) : zero;
  __m512 a4 = NV > 4 ? load(b + i0, 4) : zero;
  __m512 a5 = NV > 5 ? load(b + i0, 5) : zero;
  __m512 a6 = NV > 6 ? load(b + i0, 6) : zero;
  __m512 a7 = NV > 7 ? load(b + i0, 7) : zero;
  for (int j = 0; j < in; ++j) {
    const float* col = w + static_cast<std::ptrdiff_t>(j) * out + i0;
    const __m512 xj = _mm512_set1_ps(x[j]);
    a0 = _mm512_fmadd_ps(load(col, 0), xj, a0);
    if constexpr (NV > 1) a1 = _mm512_fmadd_ps(load(col, 1), xj, a1);
    if constexpr (NV > 2) a2 = _mm512_fmadd_ps(load(col, 2), xj, a2);
    if constexpr (NV > 3) a3 = _mm512_fmadd_ps(load(col, 3), xj, a3);
    if constexpr (NV > 4) a4 = _mm512_fmadd_ps(load(col, 4), xj, a4);
    if constexpr (NV > 5) a5 = _mm512_fmadd_ps(load(col, 5), xj, a5);
    if constexpr (NV > 6) a6 = _mm512_fmadd_ps(load(col, 6), xj, a6);
    if constexpr (NV > 7) a7 = _mm512_fmadd_ps(load(col, 7), xj, a7);
  }
  const __m512 acc[8] = {a0, a1, a2, a3, a4, a5, a6, a7};
  for (int v = 0; v < NV; ++v) {
    const __m512 r = relu ? _mm512_max_ps(acc[v], zero) : acc[v];
    _mm512_mask_storeu_ps(y + i0 + 16 * v, mask(v), r);
  }
}

// At most 16 outputs: four chains over the columns, summed at the end.
void Narrow(const float* w, int out, int in, const float* x, const float* b, bool relu, float* y,
            __mmask16 tail) {
  __m512 acc[4] = {_mm512_maskz_loadu_ps(tail, b), _mm512_setzero_ps(), _mm512_setzero_ps(),
                   _mm512_setzero_ps()};
  int j = 0;
  for (; j + 4 <= in; j += 4) {
    for (int c = 0; c < 4; ++c) {
      const float* col = w + static_cast<std::ptrdiff_t>(j + c) * out;
      acc[c] = _mm512_fmadd_ps(_mm512_maskz_loadu_ps(tail, col), _mm512_set1_ps(x[j + c]), acc[c]);
    }
  }
  for (; j < in; ++j) {
    const float* col = w + static_cast<std::ptrdiff_t>(j) * out;
    acc[0] = _mm512_fmadd_ps(_mm512_maskz_loadu_ps(tail, col), _mm512_set1_ps(x[j]), acc[0]);
  }
  __m512 sum = _mm512_add_ps(_mm512_add_ps(acc[0], acc[1]), _mm512_add_ps(acc[2], acc[3]));
  if (relu) sum = _mm512_max_ps(sum, _mm512_setzero_ps());
  _mm512_mask_storeu_ps(y, tail, sum);
}
#endif

// Outputs [i_begin, i_end) of Gemv(), i_begin a multiple of kBlockRows.
void GemvRows(const float* w, int out, int in, const float* x, const float* b, bool relu, float* y,
              int i_begin, int i_end) {
#if RL_NN_AVX512
  if (out <= 16) {
    Narrow(w, out, in, x, b, relu, y, static_cast<__mmask16>((1U << out) - 1U));
    return;
  }
  // Blocks of up to 8 registers (128 outputs), each a single pass over the columns.
  for (int i0 = i_begin; i0 < i_end; i0 += kBlockRows) {
    const int rows = std::min(kBlockRows, i_end - i0);
    const int nv = (rows + 15) / 16;
    const int last = rows - 16 * (nv - 1);
    const auto tail = static_cast<__mmask16>(last == 16 ? 0xFFFFU : (1U << last) - 1U);
    switch (nv) {
      case 1:
        GemvBlock<1>(w, out, in, x, b, relu, y, i0, tail);
        break;
      case 2:
        GemvBlock<2>(w, out, in, x, b, relu, y, i0, tail);
        break;
      case 3:
        GemvBlock<3>(w, out, in, x, b, relu, y, i0, tail);
        break;
      case 4:
        GemvBlock<4>(w, out, in, x, b, relu, y, i0, tail);
        break;
      case 5:
        GemvBlock<5>(w, out, in, x, b, relu, y, i0, tail);
        break;
      case 6:
        GemvBlock<6>(w, out, in, x, b, relu, y, i0, tail);
        break;
      case 7:
        GemvBlock<7>(w, out, in, x, b, relu, y, i0, tail);
        break;
      default:
        GemvBlock<8>(w, out, in, x, b, relu, y, i0, tail);
        break;
    }
  }
#else
  // Portable: the same column walk, vectorised by the compiler over the outputs.
  std::copy(b + i_begin, b + i_end, y + i_begin);
  for (int j = 0; j < in; ++j) {
    const float* col = w + static_cast<std::ptrdiff_t>(j) * out;
    const float xj = x[j];
    for (int i = i_begin; i < i_end; ++i) y[i] += col[i] * xj;
  }
  if (relu) {
    for (int i = i_begin; i < i_end; ++i) y[i] = std::max(y[i], 0.0f);
  }
#endif
}

}  // namespace
}  // namespace rl::nn::internal::RL_NN_ISA
