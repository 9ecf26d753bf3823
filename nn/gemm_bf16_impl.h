// bf16 products on AVX512_BF16: both operands rounded to bfloat16 (vcvtne2ps2bf16: to nearest,
// ties to even) as they are packed, pairs of them along the shared dimension in 32-bit words, and
// multiplied with vdpbf16ps, which adds the two products of a pair to an fp32 sum. Included by
// kernels_avx512_bf16.cc only, inside the namespace of its instruction set (RL_NN_ISA), after
// gemm_block_impl.h.
#ifndef RL_NN_ISA
#error "nn/gemm_bf16_impl.h is included by kernels_avx512_bf16.cc only"
#endif

namespace rl::nn::internal::RL_NN_ISA {
namespace {

// Register blocking: kMaxV x kNrB accumulators of 16 floats (24 of the 32 registers), so panels
// of A are 48 rows and a micro-kernel call computes 48 x 8 results.
constexpr int kL = 16;
constexpr int kMaxV = 3;
constexpr int kNrB = 8;
constexpr int kMrB = kMaxV * kL;
// Pairs of the shared dimension per slice: a packed panel of 48 x 128 pairs (24 KB) stays in L1
// while B streams by.
constexpr int kKcPairs = 128;

using Acc [[gnu::vector_size(kL * sizeof(float))]] = float;
// Two bfloat16 in one 32-bit word: the one of the even index of the shared dimension in the low
// half, the odd one in the high half, as vdpbf16ps pairs them.
using Pair = uint32_t;

// bf16 pairs (even[i], odd[i]) of 16 lanes.
inline __m512i PairUp(__m512 even, __m512 odd) {
  const __m512i interleave =
      _mm512_set_epi16(31, 15, 30, 14, 29, 13, 28, 12, 27, 11, 26, 10, 25, 9, 24, 8, 23, 7, 22, 6,
                       21, 5, 20, 4, 19, 3, 18, 2, 17, 1, 16, 0);
  return _mm512_permutexvar_epi16(interleave, (__m512i)_mm512_cvtne2ps_pbh(odd, even));
}

// The 16 pairs of 32 consecutive floats, of which the first `valid` (<= 32) are read and the
// rest taken as 0.
inline __m512i PairsOfRun(const float* src, int valid) {
  if (valid >= 32) {
    return (__m512i)_mm512_cvtne2ps_pbh(_mm512_loadu_ps(src + 16), _mm512_loadu_ps(src));
  }
  const auto lo_mask = static_cast<__mmask16>(valid >= 16 ? 0xFFFFU : (1U << valid) - 1U);
  const auto hi_mask = static_cast<__mmask16>(valid >= 32   ? 0xFFFFU
                                              : valid <= 16 ? 0U
                                                            : (1U << (valid - 16)) - 1U);
  const __m512 lo = _mm512_maskz_loadu_ps(lo_mask, src);
  const __m512 hi = _mm512_maskz_loadu_ps(hi_mask, src + 16);
  return (__m512i)_mm512_cvtne2ps_pbh(hi, lo);
}

// The first n lanes (none for n <= 0: the padding rows of a panel).
inline __mmask16 FirstLanes(int n) {
  if (n <= 0) return 0;
  return static_cast<__mmask16>(n >= 16 ? 0xFFFFU : (1U << n) - 1U);
}

// In-register transpose of 16 x 16 32-bit words: r[i] lane j becomes r[j] lane i.
inline void Transpose16(__m512i* r) {
  __m512i t[16];
#pragma GCC unroll 8
  for (int i = 0; i < 8; ++i) {
    t[2 * i] = _mm512_unpacklo_epi32(r[2 * i], r[2 * i + 1]);
    t[2 * i + 1] = _mm512_unpackhi_epi32(r[2 * i], r[2 * i + 1]);
  }
  // Now block b (128 bits) of r[4 i + e] holds element 4 b + e of rows 4 i .. 4 i + 3.
#pragma GCC unroll 4
  for (int i = 0; i < 4; ++i) {
    r[4 * i] = _mm512_unpacklo_epi64(t[4 * i], t[4 * i + 2]);
    r[4 * i + 1] = _mm512_unpackhi_epi64(t[4 * i], t[4 * i + 2]);
    r[4 * i + 2] = _mm512_unpacklo_epi64(t[4 * i + 1], t[4 * i + 3]);
    r[4 * i + 3] = _mm512_unpackhi_epi64(t[4 * i + 1], t[4 * i + 3]);
  }
#pragma GCC unroll 4
  for (int e = 0; e < 4; ++e) {
    const __m512i p = _mm512_shuffle_i32x4(r[e], r[4 + e], 0x88);
    const __m512i q = _mm512_shuffle_i32x4(r[e], r[4 + e], 0xDD);
    const __m512i s = _mm512_shuffle_i32x4(r[8 + e], r[12 + e], 0x88);
    const __m512i u = _mm512_shuffle_i32x4(r[8 + e], r[12 + e], 0xDD);
    t[e] = _mm512_shuffle_i32x4(p, s, 0x88);
    t[4 + e] = _mm512_shuffle_i32x4(q, u, 0x88);
    t[8 + e] = _mm512_shuffle_i32x4(p, s, 0xDD);
    t[12 + e] = _mm512_shuffle_i32x4(q, u, 0xDD);
  }
#pragma GCC unroll 16
  for (int i = 0; i < 16; ++i) r[i] = t[i];
}

// Pairs [q0, q0 + pairs) of the shared dimension of `rows` rows whose entries for one index of
// the shared dimension are contiguous: index p of row i at src[i + p * stride] (p < k). Writes
// pair q, rows [0, width) at dst[(q - q0) * dst_step + i], zeros past `rows` (width: a multiple
// of 16).
void PairsFromColumns(const float* src, int64_t stride, int rows, int k, int q0, int pairs,
                      int width, int64_t dst_step, Pair* dst) {
  // A stride of whole rows of a large matrix (a weight) crosses a page every pair or two, where
  // the hardware does not prefetch: ask for the pair kAheadPairs on.
  constexpr int kAheadPairs = 4;
  const bool prefetch = stride >= 256;
  for (int q = q0; q < q0 + pairs; ++q) {
    const float* even = src + 2 * static_cast<int64_t>(q) * stride;
    const bool has_odd = 2 * q + 1 < k;
    Pair* out = dst + (q - q0) * dst_step;
    if (prefetch && 2 * (q + kAheadPairs) + 1 < k) {
      const float* ahead = even + 2 * kAheadPairs * stride;
      for (int i = 0; i < rows; i += 16) {
        __builtin_prefetch(ahead + i);
        __builtin_prefetch(ahead + stride + i);
      }
    }
    for (int i = 0; i < width; i += 16) {
      if (rows - i >= 16 && has_odd) {
        _mm512_storeu_si512(out + i,
                            PairUp(_mm512_loadu_ps(even + i), _mm512_loadu_ps(even + stride + i)));
        continue;
      }
      const __mmask16 mask = FirstLanes(rows - i);
      const __m512 e = _mm512_maskz_loadu_ps(mask, even + i);
      const __m512 o =
          has_odd ? _mm512_maskz_loadu_ps(mask, even + stride + i) : _mm512_setzero_ps();
      _mm512_storeu_si512(out + i, PairUp(e, o));
    }
  }
}

// The same for rows whose entries along the shared dimension are contiguous: index p of row i at
// src[i * stride + p]. Converts 16 x 16 pairs at a time and transposes them in registers.
void PairsFromRows(const float* src, int64_t stride, int rows, int k, int q0, int pairs, int width,
                   int64_t dst_step, Pair* dst) {
  for (int i0 = 0; i0 < width; i0 += 16) {
    for (int qb = q0; qb < q0 + pairs; qb += 16) {
      const int block = std::min(16, q0 + pairs - qb);
      const int valid = std::min(32, k - 2 * qb);
      __m512i r[16];
#pragma GCC unroll 16
      for (int i = 0; i < 16; ++i) {
        r[i] = i0 + i < rows ? PairsOfRun(src + (i0 + i) * stride + 2 * qb, valid)
                             : _mm512_setzero_si512();
      }
      Transpose16(r);
      for (int q = 0; q < block; ++q)
        _mm512_storeu_si512(dst + (qb - q0 + q) * dst_step + i0, r[q]);
    }
  }
}

// Any strides: one element at a time.
void PairsAnyStrides(const ConstView& a, int i0, int rows, int q0, int pairs, int width,
                     int64_t dst_step, Pair* dst) {
  for (int q = q0; q < q0 + pairs; ++q) {
    for (int i = 0; i < width; ++i) {
      Pair pair = 0;
      for (int h = 0; h < 2; ++h) {
        const int p = 2 * q + h;
        if (i >= rows || p >= a.cols) continue;
        const float x = RoundToBf16(a.data[(i0 + i) * a.row_stride + p * a.col_stride]);
        uint32_t bits = 0;
        std::memcpy(&bits, &x, sizeof(bits));
        pair |= (bits >> 16) << (16 * h);
      }
      dst[(q - q0) * dst_step + i] = pair;
    }
  }
}

// Rows [i0, i0 + rows) of `a`, pairs [q0, q0 + pairs): pair q of row i at dst[(q - q0) *
// dst_step + i], rows [rows, width) zero.
void PackPairs(const ConstView& a, int i0, int rows, int q0, int pairs, int width, int64_t dst_step,
               Pair* dst) {
  if (a.row_stride == 1) {
    PairsFromColumns(a.data + i0, a.col_stride, rows, a.cols, q0, pairs, width, dst_step, dst);
  } else if (a.col_stride == 1) {
    PairsFromRows(a.data + i0 * a.row_stride, a.row_stride, rows, a.cols, q0, pairs, width,
                  dst_step, dst);
  } else {
    PairsAnyStrides(a, i0, rows, q0, pairs, width, dst_step, dst);
  }
}

// B (k x n) as pairs along k: pair q of column j at dst[q * brs + j * bcs]. Columns of B that are
// contiguous along k are converted one by one (brs 1); rows contiguous along n are interleaved
// two at a time (bcs 1).
struct PackedB {
  bool by_rows;  // Rows interleaved (bcs 1), else columns converted (brs 1).
  int64_t brs;
  int64_t bcs;
  int64_t size;  // Pairs.
};

PackedB LayoutOfB(const ConstView& b) {
  const int pairs = (b.rows + 1) / 2;
  if (b.col_stride == 1 && b.row_stride != 1) {
    const int width = (b.cols + 15) / 16 * 16;
    return {true, width, 1, static_cast<int64_t>(pairs) * width};
  }
  return {false, 1, pairs, static_cast<int64_t>(pairs) * b.cols};
}

void PackB(const ConstView& b, const PackedB& layout, Pair* dst) {
  const int pairs = (b.rows + 1) / 2;
  if (layout.by_rows) {
    const int width = static_cast<int>(layout.brs);
    return PairsFromColumns(b.data, b.row_stride, b.cols, b.rows, 0, pairs, width, width, dst);
  }
  if (b.row_stride == 1) {
    for (int j = 0; j < b.cols; ++j) {
      const float* col = b.data + j * b.col_stride;
      Pair* out = dst + j * layout.bcs;
      for (int q = 0; q < pairs; q += 16) {
        const __m512i v = PairsOfRun(col + 2 * q, std::min(32, b.rows - 2 * q));
        _mm512_mask_storeu_epi32(out + q, FirstLanes(pairs - q), v);
      }
    }
    return;
  }
  // B^T is b.cols x b.rows; its "rows along the shared dimension" are B's columns.
  for (int j = 0; j < b.cols; ++j) {
    PairsAnyStrides(b.Transposed(), j, 1, 0, pairs, 1, layout.bcs, dst + j * layout.bcs);
  }
}

// Computes the V*16 x NR block c (=|+=) bias + A_panel * B over k2 pairs, then the activation
// steps. `ap`: k2 steps of V*16 pairs, `a_step` apart; `b`: pair q of column j at
// b[q * brs + j * bcs].
template <int V, int NR>
void MicroKernelBf16(int k2, const Pair* ap, int64_t a_step, const Pair* b, int64_t brs,
                     int64_t bcs, const Block& out) {
  Acc acc[V][NR];
  InitAccumulators<Acc, kL>(out, acc);
  for (int q = 0; q < k2; ++q) {
    __m512bh a[V];
#pragma GCC unroll 4
    for (int i = 0; i < V; ++i) a[i] = (__m512bh)_mm512_loadu_si512(ap + i * kL);
    ap += a_step;
    const Pair* bp = b + q * brs;
#pragma GCC unroll 16
    for (int j = 0; j < NR; ++j) {
      const auto bj = (__m512bh)_mm512_set1_epi32(static_cast<int>(bp[j * bcs]));
#pragma GCC unroll 4
      for (int i = 0; i < V; ++i) acc[i][j] = (Acc)_mm512_dpbf16_ps((__m512)acc[i][j], a[i], bj);
    }
  }
  StoreAccumulators<Acc, kL>(acc, out);
}

using KernelBf16Fn = void (*)(int, const Pair*, int64_t, const Pair*, int64_t, int64_t,
                              const Block&);

template <int V, int... NR>
constexpr std::array<KernelBf16Fn, kNrB + 1> KernelRowBf16(
    std::integer_sequence<int, NR...> /*unused*/) {
  return {nullptr, &MicroKernelBf16<V, NR + 1>...};
}
template <int... V>
constexpr auto KernelTableBf16(std::integer_sequence<int, V...> /*unused*/) {
  return std::array<std::array<KernelBf16Fn, kNrB + 1>, kMaxV>{
      KernelRowBf16<V + 1>(std::make_integer_sequence<int, kNrB>{})...};
}
// kKernelsBf16[V - 1][NR] is MicroKernelBf16<V, NR>.
constexpr auto kKernelsBf16 = KernelTableBf16(std::make_integer_sequence<int, kMaxV>{});

// Where the rows of A come from: `a` itself, fp32 panels of kMrB rows (GemmPacked() in
// nn/gemm.h), or panels already in bf16 pairs (GemmPackedPairs()); with either of the last two,
// `a` is only a shape.
struct PackedA {
  const float* floats = nullptr;
  const Pair* pairs = nullptr;
};

// The whole product for k > 0: B packed once, then slices of kKcPairs pairs, panel by panel.
void PanelGemmBf16(const ConstView& a, const ConstView& b, const MutView& c, bool accumulate,
                   const Epilogue& epilogue, Vector* workspace, const PackedA& prepacked) {
  const int m = c.rows;
  const int n = c.cols;
  const int k = a.cols;
  const int k2 = (k + 1) / 2;
  const int panels = (m + kMrB - 1) / kMrB;
  const PackedB layout = LayoutOfB(b);
  // Workspace: packed B, one packed panel slice, the bias of a panel (floats and pairs are both
  // 4 bytes).
  const int64_t panel_pairs = static_cast<int64_t>(kMrB) * std::min(k2, kKcPairs);
  const int64_t needed = layout.size + panel_pairs + kMrB;
  if (workspace->size() < needed) workspace->resize(needed);
  auto* packed_b = reinterpret_cast<Pair*>(workspace->data());
  Pair* packed_a = packed_b + layout.size;
  float* bias_panel = workspace->data() + layout.size + panel_pairs;
  PackB(b, layout, packed_b);

  for (int q0 = 0; q0 < k2; q0 += kKcPairs) {
    const int kc2 = std::min(kKcPairs, k2 - q0);
    // Only the first slice may overwrite c or add the bias, only the last one applies the
    // activation steps.
    const bool first = q0 == 0;
    const bool last = q0 + kc2 == k2;
    for (int q = 0; q < panels; ++q) {
      const int i0 = q * kMrB;
      const int rows = std::min(kMrB, m - i0);
      const int vecs = (rows + kL - 1) / kL;
      const int mr = vecs * kL;
      const Pair* ap = packed_a;
      int64_t a_step = mr;
      if (prepacked.pairs != nullptr) {
        ap = prepacked.pairs + (static_cast<int64_t>(q) * k2 + q0) * kMrB;
        a_step = kMrB;
      } else if (prepacked.floats != nullptr) {
        PairsFromColumns(prepacked.floats + static_cast<int64_t>(q) * kMrB * k, kMrB, rows, k, q0,
                         kc2, mr, mr, packed_a);
      } else {
        PackPairs(a, i0, rows, q0, kc2, mr, mr, packed_a);
      }
      const float* mask_rows = nullptr;
      Block out =
          PanelBlock(c, i0, rows, mr, first, last, accumulate, epilogue, bias_panel, &mask_rows);
      float* c_rows = out.c;
      const Pair* b_slice = packed_b + q0 * layout.brs;
      for (int j0 = 0; j0 < n; j0 += kNrB) {
        const int nr = std::min(kNrB, n - j0);
        out.c = c_rows + j0 * c.col_stride;
        out.mask = mask_rows != nullptr ? mask_rows + j0 * c.col_stride : nullptr;
        out.col_bias = first && epilogue.col_bias != nullptr ? epilogue.col_bias + j0 : nullptr;
        kKernelsBf16[static_cast<size_t>(vecs - 1)][static_cast<size_t>(nr)](
            kc2, ap, a_step, b_slice + j0 * layout.bcs, layout.brs, layout.bcs, out);
      }
    }
  }
}

}  // namespace

void GemmOneBf16(const ConstView& a, const ConstView& b, const MutView& c, bool accumulate,
                 const Epilogue& epilogue, Vector* workspace) {
  if (c.rows == 0 || c.cols == 0) return;
  // nn/gemm.cc sends products without a shared dimension and those too small for panels to the
  // fp32 kernels; should one arrive here, the fp32 kernel computes it.
  if (a.cols == 0) return avx512::GemmOne(a, b, c, accumulate, epilogue, workspace);
  PanelGemmBf16(a, b, c, accumulate, epilogue, workspace, {});
}

void GemmPackedOneBf16(const float* a_packed, int m, int k, const ConstView& b, const MutView& c,
                       bool accumulate, const Epilogue& epilogue, Vector* workspace) {
  PanelGemmBf16({nullptr, m, k, 0, 0}, b, c, accumulate, epilogue, workspace, {a_packed, nullptr});
}

void GemmPairsOneBf16(const uint32_t* a_pairs, int m, int k, const ConstView& b, const MutView& c,
                      bool accumulate, const Epilogue& epilogue, Vector* workspace) {
  PanelGemmBf16({nullptr, m, k, 0, 0}, b, c, accumulate, epilogue, workspace, {nullptr, a_pairs});
}

// Rows [i0, i0 + rows) of `a` (i0 a multiple of kMrB) rounded into the bf16 pairs of
// GemmPackedPairs(), panel i0 / kMrB first, at `pairs`.
void RoundIntoPairs(const ConstView& a, int i0, int rows, uint32_t* pairs) {
  const int k2 = (a.cols + 1) / 2;
  for (int r = 0; r < rows; r += kMrB) {
    PackPairs(a, i0 + r, std::min(kMrB, rows - r), 0, k2, kMrB, kMrB,
              pairs + static_cast<int64_t>(r) * k2);
  }
}

// The convolution's unfolding (conv_impl.h's Im2colPanels()) straight into bf16 pairs, a panel
// at a time: every pair of taps reads its two panel rows into registers (panel_gather_impl.h),
// rounds and pairs them, and stores the pairs, one whole store per vector and tap pair.
void Im2colPairs(const ConvGeometry& g, const float* planes, int count, uint32_t* pairs) {
  const int64_t m = static_cast<int64_t>(count) * g.pixels;
  const int64_t panels = (m + kMrB - 1) / kMrB;
  const int steps = (g.taps + 1) / 2;
  std::array<PanelPiece, kMrB> pieces{};
  std::array<PanelLoad, kMaxV * kMaxLoadsPerVector> loads{};
  std::array<int, kMaxV + 1> first{};
  for (int64_t q = 0; q < panels; ++q) {
    const int n_pieces = PanelPieces(g, q, kMrB, m, pieces.data());
    PlanPanelLoads(pieces.data(), n_pieces, kMaxV, loads.data(), first.data());
    Pair* dst = pairs + q * kMrB * steps;
    for (int tap = 0; tap < g.taps; tap += 2, dst += kMrB) {
      const float* even = planes + g.tap_offset[static_cast<size_t>(tap)];
      // An odd number of taps pairs the last one with zeros.
      const bool has_odd = tap + 1 < g.taps;
      const float* odd = has_odd ? planes + g.tap_offset[static_cast<size_t>(tap) + 1] : nullptr;
#pragma GCC unroll 3
      for (int v = 0; v < kMaxV; ++v) {
        const VectorLoads vector_loads = LoadsOfVector(loads.data(), first.data(), v);
        const __m512 e = GatherVector(vector_loads, even);
        const __m512 o = has_odd ? GatherVector(vector_loads, odd) : _mm512_setzero_ps();
        _mm512_storeu_si512(dst + v * kL, PairUp(e, o));
      }
    }
  }
}

}  // namespace rl::nn::internal::RL_NN_ISA
