// The convolution kernels of one path: the copies that split rows into phase planes and back,
// the unfolding (im2col) and the gradient of a phase plane (see Conv2d in nn/conv2d.h). Included
// by the kernels_*.cc files only, inside the namespace of their instruction set (RL_NN_ISA).
#ifndef RL_NN_ISA
#error "nn/conv_impl.h is included by the kernels_*.cc files only"
#endif

namespace rl::nn::internal::RL_NN_ISA {
namespace {

// dst[0, n) = src[0, n).
inline void CopyRun(const float* src, int n, float* dst) {
#if RL_NN_AVX512
  int i = 0;
  for (; i + 16 <= n; i += 16) _mm512_storeu_ps(dst + i, _mm512_loadu_ps(src + i));
  if (i < n) {
    const auto m = static_cast<__mmask16>((1U << (n - i)) - 1U);
    _mm512_mask_storeu_ps(dst + i, m, _mm512_maskz_loadu_ps(m, src + i));
  }
#else
  std::copy_n(src, n, dst);
#endif
}

#if RL_NN_AVX512
// The floats p[0, lanes) in the low lanes and 0 in the others, reading only [p - behind,
// p + lanes). A masked load is several times slower than a plain one on memory not yet in the
// cache on some CPUs (AMD Zen 4 and 5), so when 16 readable floats end at p + lanes the part
// is read by a plain load of those and moved down by a permute.
inline __m512 LoadFirst(const float* p, int lanes, int64_t behind) {
  if (lanes >= 16) return _mm512_loadu_ps(p);
  if (lanes <= 0) return _mm512_setzero_ps();
  const auto mask = static_cast<__mmask16>((1U << lanes) - 1U);
  if (behind + lanes < 16) return _mm512_maskz_loadu_ps(mask, p);
  const __m512i up =
      _mm512_add_epi32(_mm512_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15),
                       _mm512_set1_epi32(16 - lanes));
  return _mm512_maskz_permutexvar_ps(mask, up, _mm512_loadu_ps(p + lanes - 16));
}
#endif

// Splits the row `src` of n * s floats, of which the first `valid` are read and the rest taken
// as 0, into s rows of n: dst[px * plane_size + x] = src[x * s + px]. Unrolled for the common
// strides so that the compiler vectorises it, and with AVX-512 permutes for strides 2 and 4 (the
// Nature network's).
template <int S>
void DeinterleaveFixed(const float* __restrict src, int valid, int n, int64_t plane_size,
                       float* __restrict dst) {
#if RL_NN_AVX512
  if constexpr (S == 2 || S == 4) {
    // Output px takes lanes px, px + S, ... of 16 S consecutive inputs: for S = 2 one two-source
    // permute; for S = 4 eight lanes from each half of them, then the halves joined. Loads stop
    // at `valid` (the lanes past it read as 0, see LoadFirst()) and the last chunk stores only
    // the lanes it has.
    const __m512i stride_idx = _mm512_mullo_epi32(
        _mm512_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7, 0, 1, 2, 3, 4, 5, 6, 7), _mm512_set1_epi32(S));
    const __m512i idx2 =
        _mm512_setr_epi32(0, 2, 4, 6, 8, 10, 12, 14, 16, 18, 20, 22, 24, 26, 28, 30);
    for (int x0 = 0; x0 < n; x0 += 16) {
      const int count = std::min(16, n - x0);
      const int floats = std::min(count * S, valid - S * x0);
      __m512 v[S];
#pragma GCC unroll 4
      for (int i = 0; i < S; ++i) {
        v[i] = LoadFirst(src + S * x0 + 16 * i, floats - 16 * i, S * x0 + 16 * i);
      }
      const auto out_mask = static_cast<__mmask16>((1U << count) - 1U);
#pragma GCC unroll 4
      for (int px = 0; px < S; ++px) {
        __m512 out;
        if constexpr (S == 2) {
          out = _mm512_permutex2var_ps(v[0], _mm512_add_epi32(idx2, _mm512_set1_epi32(px)), v[1]);
        } else {
          const __m512i idx = _mm512_add_epi32(stride_idx, _mm512_set1_epi32(px));
          out = _mm512_shuffle_f32x4(_mm512_permutex2var_ps(v[0], idx, v[1]),
                                     _mm512_permutex2var_ps(v[2], idx, v[3]), 0x44);
        }
        if (count == 16) {
          _mm512_storeu_ps(dst + px * plane_size + x0, out);
        } else {
          _mm512_mask_storeu_ps(dst + px * plane_size + x0, out_mask, out);
        }
      }
    }
    return;
  }
#endif
  for (int x = 0; x < n; ++x) {
#pragma GCC unroll 4
    for (int px = 0; px < S; ++px) {
      const int i = x * S + px;
      dst[px * plane_size + x] = i < valid ? src[i] : 0.0f;
    }
  }
}

void Deinterleave(const float* src, int valid, int s, int n, int64_t plane_size, float* dst) {
  switch (s) {
    case 1:
      std::copy(src, src + std::min(valid, n), dst);
      std::fill(dst + std::min(valid, n), dst + n, 0.0f);
      return;
    case 2:
      return DeinterleaveFixed<2>(src, valid, n, plane_size, dst);
    case 4:
      return DeinterleaveFixed<4>(src, valid, n, plane_size, dst);
    default:
      for (int x = 0; x < n; ++x) {
        for (int px = 0; px < s; ++px) {
          const int i = x * s + px;
          dst[px * plane_size + x] = i < valid ? src[i] : 0.0f;
        }
      }
  }
}

// The inverse of Deinterleave(): dst[x * s + px] = src[px * plane_size + x].
template <int S>
void InterleaveFixed(const float* __restrict src, int n, int64_t plane_size,
                     float* __restrict dst) {
  int x0 = 0;
#if RL_NN_AVX512
  if constexpr (S == 2) {
    // Lanes 0, 16, 1, 17, ... of the two planes' 16 pixels, then lanes 8, 24, 9, 25, ...
    const __m512i low = _mm512_setr_epi32(0, 16, 1, 17, 2, 18, 3, 19, 4, 20, 5, 21, 6, 22, 7, 23);
    const __m512i high = _mm512_add_epi32(low, _mm512_set1_epi32(8));
    for (; x0 + 16 <= n; x0 += 16) {
      const __m512 a = _mm512_loadu_ps(src + x0);
      const __m512 b = _mm512_loadu_ps(src + plane_size + x0);
      _mm512_storeu_ps(dst + 2 * x0, _mm512_permutex2var_ps(a, low, b));
      _mm512_storeu_ps(dst + 2 * x0 + 16, _mm512_permutex2var_ps(a, high, b));
    }
  }
#endif
  for (int x = x0; x < n; ++x) {
#pragma GCC unroll 4
    for (int px = 0; px < S; ++px) dst[x * S + px] = src[px * plane_size + x];
  }
}

void Interleave(const float* src, int s, int n, int64_t plane_size, float* dst) {
  switch (s) {
    case 1:
      std::copy(src, src + n, dst);
      return;
    case 2:
      return InterleaveFixed<2>(src, n, plane_size, dst);
    case 4:
      return InterleaveFixed<4>(src, n, plane_size, dst);
    default:
      for (int x = 0; x < n; ++x) {
        for (int px = 0; px < s; ++px) dst[x * s + px] = src[px * plane_size + x];
      }
  }
}

void CopyRuns(const float* src, int64_t src_step, float* dst, int64_t dst_step, int runs, int len) {
  for (int r = 0; r < runs; ++r) CopyRun(src + r * src_step, len, dst + r * dst_step);
}

// Column (c, ky, kx) of the unfolded matrix, row (sample, oy, ox), holds the padded input pixel
// (oy * s + ky, ox * s + kx) of channel c: pixel (oy + ky / s, ox + kx / s) of phase plane
// (c, ky % s, kx % s). For each output row that is a contiguous run of ow plane pixels.
void Im2col(const ConvGeometry& g, const float* planes, int count, float* cols) {
  const int64_t m = static_cast<int64_t>(count) * g.pixels;
  for (int tap = 0; tap < g.taps; ++tap) {
    const float* src0 = planes + g.tap_offset[static_cast<size_t>(tap)];
    float* dst = cols + tap * m;
#if RL_NN_AVX512
    if (g.window_span <= 16) {
      // The whole oh x ow window lies within 16 consecutive plane floats: one load, one permute
      // and one store per sample.
      const auto load_mask = static_cast<__mmask16>((1U << g.window_span) - 1U);
      const auto store_mask = static_cast<__mmask16>((1U << g.pixels) - 1U);
      const __m512i window = _mm512_loadu_si512(g.window_index.data());
      for (int t = 0; t < count; ++t) {
        const __m512 v = _mm512_maskz_loadu_ps(load_mask, src0 + t * g.plane_stride);
        _mm512_mask_storeu_ps(dst, store_mask, _mm512_permutexvar_ps(window, v));
        dst += g.pixels;
      }
      continue;
    }
#endif
    for (int t = 0; t < count; ++t) {
      const float* src = src0 + t * g.plane_stride;
      if (g.plane_w == g.out_w) {
        CopyRun(src, g.pixels, dst);
        dst += g.pixels;
        continue;
      }
      for (int oy = 0; oy < g.out_h; ++oy) {
        CopyRun(src + static_cast<int64_t>(oy) * g.plane_w, g.out_w, dst);
        dst += g.out_w;
      }
    }
  }
}

// Panel by panel, so that the writes are sequential: the panel's rows (sample, oy, ox) fall into
// a few runs of consecutive ox, each a run of consecutive plane pixels, which every tap copies
// from its own plane and offset (tap_offset).
void Im2colPanels(const ConvGeometry& g, const float* planes, int count, int panel_rows,
                  float* cols) {
  constexpr int kMaxPanelRows = 64;
  const int64_t m = static_cast<int64_t>(count) * g.pixels;
  const int64_t panels = (m + panel_rows - 1) / panel_rows;
  std::array<PanelPiece, kMaxPanelRows> pieces{};
#if RL_NN_AVX512
  // Whole vectors of a tap's panel row gathered in registers (panel_gather_impl.h): one store
  // each, where copying the pieces one by one stores each in parts.
  if (panel_rows % 16 == 0) {
    constexpr int kMaxVectors = kMaxPanelRows / 16;
    const int vectors = panel_rows / 16;
    std::array<PanelLoad, kMaxVectors * kMaxLoadsPerVector> loads{};
    std::array<int, kMaxVectors + 1> first{};
    for (int64_t q = 0; q < panels; ++q) {
      const int n_pieces = PanelPieces(g, q, panel_rows, m, pieces.data());
      PlanPanelLoads(pieces.data(), n_pieces, vectors, loads.data(), first.data());
      float* dst = cols + q * panel_rows * g.taps;
      for (int tap = 0; tap < g.taps; ++tap, dst += panel_rows) {
        const float* src = planes + g.tap_offset[static_cast<size_t>(tap)];
        for (int v = 0; v < vectors; ++v) {
          _mm512_storeu_ps(dst + v * 16,
                           GatherVector(LoadsOfVector(loads.data(), first.data(), v), src));
        }
      }
    }
    return;
  }
#endif
  for (int64_t q = 0; q < panels; ++q) {
    const int n_pieces = PanelPieces(g, q, panel_rows, m, pieces.data());
    float* dst = cols + q * panel_rows * g.taps;
    for (int tap = 0; tap < g.taps; ++tap, dst += panel_rows) {
      const float* src = planes + g.tap_offset[static_cast<size_t>(tap)];
      for (int i = 0; i < n_pieces; ++i) {
        const PanelPiece& piece = pieces[static_cast<size_t>(i)];
        CopyRun(src + piece.src, piece.n, dst + piece.lane);
      }
    }
  }
}

void PlaneGradient(const ConvGeometry& g, const GradientRun* runs, int n_runs, float* out) {
  const int oh = g.out_h;
  const int ow = g.out_w;
  const int n = g.plane_w;
  for (int y = 0; y < g.plane_h; ++y) {
    float* row = out + static_cast<int64_t>(y) * n;
#if RL_NN_AVX512
    for (int x0 = 0; x0 < n; x0 += 16) {
      __m512 acc = _mm512_setzero_ps();
      for (int r = 0; r < n_runs; ++r) {
        const GradientRun& run = runs[r];
        const int oy = y - run.dy;
        // Lanes x0 + l with 0 <= x0 + l - dx < ow. The unfolded gradient has at least `kernel`
        // floats of slack in front, so the address below stays inside its buffer.
        const int lo = std::max(x0, run.dx);
        const int hi = std::min(x0 + 16, run.dx + ow);
        if (oy < 0 || oy >= oh || lo >= hi) continue;
        const auto mask = static_cast<__mmask16>(((1U << (hi - lo)) - 1U) << (lo - x0));
        const float* src = run.src + static_cast<int64_t>(oy) * ow + x0 - run.dx;
        acc = _mm512_add_ps(acc, _mm512_maskz_loadu_ps(mask, src));
      }
      const int lanes = std::min(16, n - x0);
      _mm512_mask_storeu_ps(row + x0, static_cast<__mmask16>((1U << lanes) - 1U), acc);
    }
#else
    std::fill(row, row + n, 0.0f);
    for (int r = 0; r < n_runs; ++r) {
      const GradientRun& run = runs[r];
      const int oy = y - run.dy;
      if (oy < 0 || oy >= oh) continue;
      const float* src = run.src + static_cast<int64_t>(oy) * ow;
      const int hi = std::min(n, run.dx + ow);
      for (int xx = run.dx; xx < hi; ++xx) row[xx] += src[xx - run.dx];
    }
#endif
  }
}

}  // namespace
}  // namespace rl::nn::internal::RL_NN_ISA
