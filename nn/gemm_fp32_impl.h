// The fp32 products of one path: register-blocked panels (PanelGemm) and dot products for a few
// rows (SmallMGemm). Included by the kernels_*.cc files only, inside the namespace of their
// instruction set (RL_NN_ISA); RL_NN_AVX512 selects the register blocking.
#ifndef RL_NN_ISA
#error "nn/gemm_fp32_impl.h is included by the kernels_*.cc files only"
#endif

namespace rl::nn::internal::RL_NN_ISA {
namespace {

// Register blocking. A micro-kernel keeps kMaxVecs x kNr vectors of kLanes floats in registers:
// 24 accumulators when 32 vector registers exist (AVX-512), 12 when there are 16 (AVX2). With
// AVX-512 the vectors are 16 floats: on CPUs whose FMA units are 512 bits wide (the development
// machine's, measured at 2x the 256-bit rate) that doubles the rate; on those that split 512-bit
// instructions in two (Zen 4) the rate is that of 8-float vectors, and the 84-row layer of the
// DQN MLP pads to 96 rows instead of 88.
#if RL_NN_AVX512
constexpr int kLanes = 16;
constexpr int kMaxVecs = 3;
constexpr int kNr = 8;
#else
constexpr int kLanes = 8;
constexpr int kMaxVecs = 2;
constexpr int kNr = 6;
#endif
constexpr int kMaxMr = kMaxVecs * kLanes;
// Depth of one packed panel: kMaxMr x kKc floats (48 KB at most) stay near the core while B
// streams by.
constexpr int kKc = 256;
// Floats of packed A kept at once when whole blocks of panels are packed (512 KB, half of L2).
constexpr int64_t kBlockFloats = 128 * 1024;
// Columns of C ahead of the current block that PanelGemm prefetches when it accumulates.
constexpr int kPrefetchAhead = 2 * kNr;
// Products with at most this many rows use dot products (DotKernel) instead of panels.
constexpr int kMaxSmallM = 4;
// Columns of B per DotKernel call.
constexpr int kDotColumns = 4;

using Vec [[gnu::vector_size(kLanes * sizeof(float))]] = float;

inline Vec Load(const float* p) { return LoadVec<Vec>(p); }
inline void Store(float* p, Vec v) { StoreVec(p, v); }

// Computes the V*kLanes x NR block c (=|+=) bias + A_panel * B, then the activation steps. `ap` is
// the panel: k steps of V*kLanes contiguous floats, `a_step` floats apart (packed, or A itself).
// `b` points at B(0, 0) of the block.
//
// The loops over V and NR are fully unrolled so that the accumulators live in registers; a loop
// left rolled would index `acc` at run time and force it into memory.
template <int V, int NR>
void MicroKernel(int k, const float* ap, int64_t a_step, const float* b, int64_t brs, int64_t bcs,
                 const Block& out) {
  Vec acc[V][NR];
  InitAccumulators<Vec, kLanes>(out, acc);
  // Rank-1 updates: one column of the A panel times one row of B per step.
  for (int p = 0; p < k; ++p) {
    Vec a[V];
#pragma GCC unroll 8
    for (int i = 0; i < V; ++i) a[i] = Load(ap + i * kLanes);
    ap += a_step;
    const float* bp = b + p * brs;
#pragma GCC unroll 16
    for (int j = 0; j < NR; ++j) {
      const float s = bp[j * bcs];
#pragma GCC unroll 8
      for (int i = 0; i < V; ++i) acc[i][j] += a[i] * s;
    }
  }
  StoreAccumulators<Vec, kLanes>(acc, out);
}

using KernelFn = void (*)(int, const float*, int64_t, const float*, int64_t, int64_t, const Block&);

// kKernels[V - 1][NR] is MicroKernel<V, NR> (NR = 0 unused).
template <int V, int... NR>
constexpr std::array<KernelFn, kNr + 1> KernelRow(std::integer_sequence<int, NR...> /*unused*/) {
  return {nullptr, &MicroKernel<V, NR + 1>...};
}
template <int... V>
constexpr auto KernelTable(std::integer_sequence<int, V...> /*unused*/) {
  return std::array<std::array<KernelFn, kNr + 1>, kMaxVecs>{
      KernelRow<V + 1>(std::make_integer_sequence<int, kNr>{})...};
}
constexpr auto kKernels = KernelTable(std::make_integer_sequence<int, kMaxVecs>{});

// Shuffle indices for one stage of an in-register kLanes x kLanes transpose: rows i and i + B
// (i without bit B) swap their off-diagonal B x B blocks.
template <int B, bool kSecond>
constexpr std::array<int, kLanes> SwapBlockIndices() {
  std::array<int, kLanes> idx{};
  for (int l = 0; l < kLanes; ++l) {
    if (!kSecond) {
      idx[l] = (l & B) == 0 ? l : kLanes + l - B;
    } else {
      idx[l] = (l & B) == 0 ? l + B : kLanes + l;
    }
  }
  return idx;
}

template <int B, bool kSecond, int... I>
inline Vec SwapBlocks(Vec x, Vec y, std::integer_sequence<int, I...> /*unused*/) {
  constexpr std::array<int, kLanes> kIdx = SwapBlockIndices<B, kSecond>();
  return __builtin_shufflevector(x, y, kIdx[I]...);
}

template <int B>
inline void TransposeStages(Vec* rows) {
  if constexpr (B >= 1) {
    constexpr auto kSeq = std::make_integer_sequence<int, kLanes>{};
#pragma GCC unroll 16
    for (int i = 0; i < kLanes; ++i) {
      if ((i & B) != 0) continue;
      const Vec x = rows[i];
      const Vec y = rows[i | B];
      rows[i] = SwapBlocks<B, false>(x, y, kSeq);
      rows[i | B] = SwapBlocks<B, true>(x, y, kSeq);
    }
    TransposeStages<B / 2>(rows);
  }
}

// Copies rows [i0, i0 + rows) and columns [p0, p0 + k) of `a` into `dst` as k steps of `mr` floats
// (zero beyond `rows`).
void PackPanel(const ConstView& a, int i0, int rows, int p0, int k, int mr, float* dst) {
  if (a.row_stride == 1) {
    // Columns of the panel are contiguous in `a`. Copy whole vectors (a call to memcpy per column
    // costs more than the copy), then the ragged end.
    const int full = rows / kLanes;
    const float* src = a.data + i0 + p0 * a.col_stride;
    for (int p = 0; p < k; ++p, src += a.col_stride) {
      float* d = dst + static_cast<int64_t>(p) * mr;
      for (int v = 0; v < full; ++v) Store(d + v * kLanes, Load(src + v * kLanes));
      for (int i = full * kLanes; i < rows; ++i) d[i] = src[i];
      for (int i = rows; i < mr; ++i) d[i] = 0.0f;
    }
    return;
  }
  // Transposed operand. With contiguous rows, transpose kLanes x kLanes tiles in registers...
  int i_done = 0;
  int p_done = 0;
  if (a.col_stride == 1) {
    i_done = rows - rows % kLanes;
    p_done = k - k % kLanes;
    for (int ib = 0; ib < i_done; ib += kLanes) {
      const float* src = a.data + (i0 + ib) * a.row_stride + p0;
      for (int pb = 0; pb < p_done; pb += kLanes) {
        Vec tile[kLanes];
#pragma GCC unroll 16
        for (int r = 0; r < kLanes; ++r) tile[r] = Load(src + r * a.row_stride + pb);
        TransposeStages<kLanes / 2>(tile);
#pragma GCC unroll 16
        for (int t = 0; t < kLanes; ++t)
          Store(dst + static_cast<int64_t>(pb + t) * mr + ib, tile[t]);
      }
    }
  }
  // ... and copy what is left one element at a time, walking each source row contiguously.
  for (int i = 0; i < rows; ++i) {
    const float* src = a.data + (i0 + i) * a.row_stride + p0 * a.col_stride;
    for (int p = i < i_done ? p_done : 0; p < k; ++p) {
      dst[static_cast<int64_t>(p) * mr + i] = src[p * a.col_stride];
    }
  }
  for (int i = rows; i < mr; ++i) {
    for (int p = 0; p < k; ++p) dst[static_cast<int64_t>(p) * mr + i] = 0.0f;
  }
}

// Copies panels [q0, q1) of rows of a column-major `a` (row_stride 1), columns [p0, p0 + k), into
// `dst`: panel q at (q - q0) * kMaxMr * k, laid out as PackPanel() does. Walks each column of `a`
// once across all the panels, so a large A streams from memory instead of being read in short
// strided pieces.
void PackPanelBlock(const ConstView& a, int q0, int q1, int p0, int k, float* dst) {
  const int m = a.rows;
  const float* src = a.data + p0 * a.col_stride;
  for (int p = 0; p < k; ++p, src += a.col_stride) {
    for (int q = q0; q < q1; ++q) {
      const int i0 = q * kMaxMr;
      const int rows = std::min(kMaxMr, m - i0);
      const int mr = (rows + kLanes - 1) / kLanes * kLanes;
      const int full = rows / kLanes;
      float* d = dst + static_cast<int64_t>(q - q0) * kMaxMr * k + static_cast<int64_t>(p) * mr;
      const float* s = src + i0;
      for (int v = 0; v < full; ++v) Store(d + v * kLanes, Load(s + v * kLanes));
      for (int i = full * kLanes; i < rows; ++i) d[i] = s[i];
      for (int i = rows; i < mr; ++i) d[i] = 0.0f;
    }
  }
}

// The general case: panels of A times strided B, for any shapes with k > 0.
// With `prepacked`, A is only a shape and its panels are read from there (see GemmPacked()).
void PanelGemm(const ConstView& a, const ConstView& b, const MutView& c, bool accumulate,
               const Epilogue& epilogue, Vector* workspace, const float* prepacked = nullptr) {
  const int m = c.rows;
  const int n = c.cols;
  const int k = a.cols;
  const int kc_max = std::min(k, kKc);
  const int panels = (m + kMaxMr - 1) / kMaxMr;
  // A large column-major A (a weight matrix that does not fit the L2 cache) used by several
  // blocks of columns is packed a block of panels at a time (about half the L2 cache); otherwise
  // one panel at a time, which then stays in L1, or not at all.
  const bool pack_blocks = prepacked == nullptr && a.row_stride == 1 && n > kNr && panels > 1 &&
                           static_cast<int64_t>(m) * k > 2 * kBlockFloats;
  int block_panels = 1;
  if (pack_blocks) {
    const int max_panels =
        std::max<int>(1, static_cast<int>(kBlockFloats / (static_cast<int64_t>(kMaxMr) * kc_max)));
    const int blocks = (panels + max_panels - 1) / max_panels;
    block_panels = (panels + blocks - 1) / blocks;
  }
  const int64_t packed_floats = static_cast<int64_t>(block_panels) * kMaxMr * kc_max;
  if (workspace->size() < packed_floats + kMaxMr) workspace->resize(packed_floats + kMaxMr);
  float* packed = workspace->data();
  float* bias_panel = packed + packed_floats;

  for (int p0 = 0; p0 < k; p0 += kKc) {
    const int kc = std::min(kKc, k - p0);
    // Only the first slice of the shared dimension may overwrite c or add the bias, and only the
    // last one applies the activation steps.
    const bool first = p0 == 0;
    const bool last = p0 + kc == k;
    for (int q0 = 0; q0 < panels; q0 += block_panels) {
      const int q1 = std::min(panels, q0 + block_panels);
      if (pack_blocks) PackPanelBlock(a, q0, q1, p0, kc, packed);
      // While this block is multiplied, prefetch the part of A that the next one packs (a large
      // A comes from memory; without this, packing waits for it).
      int next_p0 = p0;
      int next_q0 = q0 + block_panels;
      if (next_q0 >= panels) {
        next_p0 = p0 + kKc;
        next_q0 = 0;
      }
      const bool prefetch = pack_blocks && next_p0 < k;
      const int next_kc = prefetch ? std::min(kKc, k - next_p0) : 0;
      const int next_i0 = next_q0 * kMaxMr;
      const int next_i1 = std::min(m, (next_q0 + block_panels) * kMaxMr);
      const int calls = (q1 - q0) * ((n + kNr - 1) / kNr);
      int call = 0;
      for (int q = q0; q < q1; ++q) {
        const int i0 = q * kMaxMr;
        const int rows = std::min(kMaxMr, m - i0);
        const int vecs = (rows + kLanes - 1) / kLanes;
        const int mr = vecs * kLanes;
        const float* ap = packed + static_cast<int64_t>(q - q0) * kMaxMr * kc;
        int64_t a_step = mr;
        if (prepacked != nullptr) {
          ap = prepacked + (static_cast<int64_t>(q) * k + p0) * kMaxMr;
          a_step = kMaxMr;
        } else if (!pack_blocks) {
          // With a single block of columns each panel is used once, so packing costs more than
          // it saves; full panels of a column-major A are then read in place.
          if (n <= kNr && a.row_stride == 1 && rows == mr) {
            ap = a.data + i0 + p0 * a.col_stride;
            a_step = a.col_stride;
          } else {
            PackPanel(a, i0, rows, p0, kc, mr, packed);
          }
        }
        const float* mask_rows = nullptr;
        Block out =
            PanelBlock(c, i0, rows, mr, first, last, accumulate, epilogue, bias_panel, &mask_rows);
        const std::array<KernelFn, kNr + 1>& kernels = kKernels[vecs - 1];
        const float* b_slice = b.data + p0 * b.row_stride;
        float* c_rows = out.c;
        // Blocks of kNr columns, then one narrower block for the remainder.
        for (int j0 = 0; j0 < n; j0 += kNr) {
          const int nr = std::min(kNr, n - j0);
          out.c = c_rows + j0 * c.col_stride;
          out.mask = mask_rows != nullptr ? mask_rows + j0 * c.col_stride : nullptr;
          out.col_bias = first && epilogue.col_bias != nullptr ? epilogue.col_bias + j0 : nullptr;
          if (prefetch) {
            // Columns [c0, c1) of the next block, one call's share.
            const int c0 = next_p0 + static_cast<int>(static_cast<int64_t>(next_kc) * call / calls);
            const int c1 =
                next_p0 + static_cast<int>(static_cast<int64_t>(next_kc) * (call + 1) / calls);
            for (int col = c0; col < c1; ++col) {
              const float* from = a.data + static_cast<int64_t>(col) * a.col_stride + next_i0;
              const float* to = from + (next_i1 - next_i0);
              for (const float* line = from; line < to; line += 16) {
                __builtin_prefetch(line, 0, 2);
              }
            }
            ++call;
          }
          if (out.accumulate && c.row_stride == 1 && j0 + kPrefetchAhead < n) {
            // The block of C stored kPrefetchAhead columns later: a large C (a weight gradient)
            // is read from memory.
            float* ahead = c_rows + (j0 + kPrefetchAhead) * c.col_stride;
            const int cols = std::min(kNr, n - j0 - kPrefetchAhead);
            for (int j = 0; j < cols; ++j) {
              __builtin_prefetch(ahead + j * c.col_stride, 1, 2);
              __builtin_prefetch(ahead + j * c.col_stride + rows - 1, 1, 2);
            }
          }
          kernels[nr](kc, ap, a_step, b_slice + j0 * b.col_stride, b.row_stride, b.col_stride, out);
        }
      }
    }
  }
}

constexpr int BitReverse(int x, int bits) {
  int r = 0;
  for (int i = 0; i < bits; ++i) r |= ((x >> i) & 1) << (bits - 1 - i);
  return r;
}
constexpr int Log2(int x) { return x <= 1 ? 0 : 1 + Log2(x / 2); }

// Shuffle indices that pick, from the concatenation of x and y, the first (kHigh false) or second
// halves of every group of G lanes: for each group q, G/2 lanes of x then G/2 lanes of y.
template <int G, bool kHigh>
constexpr std::array<int, kLanes> FoldIndices() {
  std::array<int, kLanes> idx{};
  const int shift = kHigh ? G / 2 : 0;
  for (int q = 0; q < kLanes / G; ++q) {
    for (int t = 0; t < G / 2; ++t) {
      idx[q * G + t] = q * G + t + shift;
      idx[q * G + G / 2 + t] = kLanes + q * G + t + shift;
    }
  }
  return idx;
}

template <int G, bool kHigh, int... I>
inline Vec FoldShuffle(Vec x, Vec y, std::integer_sequence<int, I...> /*unused*/) {
  constexpr std::array<int, kLanes> kIdx = FoldIndices<G, kHigh>();
  return __builtin_shufflevector(x, y, kIdx[I]...);
}

// Groups of G lanes of x and y become groups of G/2 lanes holding pairwise sums.
template <int G>
inline Vec Fold(Vec x, Vec y) {
  constexpr auto kSeq = std::make_integer_sequence<int, kLanes>{};
  return FoldShuffle<G, false>(x, y, kSeq) + FoldShuffle<G, true>(x, y, kSeq);
}

// Folds kCount vectors of groups of G lanes into kCount / 2 vectors of groups of G / 2, down to
// single lanes.
template <int G, int kCount>
inline void FoldLevels(Vec* v) {
  if constexpr (G > 1) {
#pragma GCC unroll 16
    for (int i = 0; i < kCount / 2; ++i) v[i] = Fold<G>(v[2 * i], v[2 * i + 1]);
    FoldLevels<G / 2, kCount / 2>(v);
  }
}

// Horizontal sums of kLanes vectors at once: lane l of the result is the sum of the lanes of v[l].
// log2(kLanes) levels of shuffles and adds instead of a scalar loop per vector.
inline Vec ReduceLanes(const Vec* v) {
  // The folds leave the sums in bit-reversed order, so feed the vectors in that order.
  Vec w[kLanes];
#pragma GCC unroll 16
  for (int l = 0; l < kLanes; ++l) w[l] = v[BitReverse(l, Log2(kLanes))];
  FoldLevels<kLanes, kLanes>(w);
  return w[0];
}

// M <= kMaxSmallM rows of C as dot products along k: C(o, j) = A(o, :) . B(:, j), vectorised
// over k, NC columns at a time. Needs contiguous columns of B. `at` holds the rows of A
// contiguously, each zero-padded to `k_pad` floats. `c` and `mask` point at column 0 of the block.
template <int M, int NC>
void DotKernel(int k, int k_pad, const float* at, const float* b, int64_t bcs,
               const Epilogue& epilogue, bool accumulate, float* c, const float* mask, int64_t crs,
               int64_t ccs) {
  constexpr int kCount = M * NC;
  constexpr int kChunks = (kCount + kLanes - 1) / kLanes;
  const int k_vec = k - k % kLanes;
  // acc[o * NC + j] accumulates row o of A times column j of B.
  Vec acc[kChunks * kLanes];
#pragma GCC unroll 32
  for (int v = 0; v < kChunks * kLanes; ++v) acc[v] = Vec{};
  for (int p = 0; p < k_vec; p += kLanes) {
    Vec bv[NC];
#pragma GCC unroll 8
    for (int j = 0; j < NC; ++j) bv[j] = Load(b + j * bcs + p);
#pragma GCC unroll 8
    for (int o = 0; o < M; ++o) {
      const Vec av = Load(at + static_cast<int64_t>(o) * k_pad + p);
#pragma GCC unroll 8
      for (int j = 0; j < NC; ++j) acc[o * NC + j] += av * bv[j];
    }
  }
  Vec sums[kChunks];
#pragma GCC unroll 4
  for (int chunk = 0; chunk < kChunks; ++chunk) sums[chunk] = ReduceLanes(acc + chunk * kLanes);
    // The k % kLanes trailing products, the epilogue and the write-back. Unrolled so that the sums
    // are read straight from registers (a scalar load from a just-stored vector stalls store
    // forwarding).
#pragma GCC unroll 8
  for (int o = 0; o < M; ++o) {
    const float* a_row = at + static_cast<int64_t>(o) * k_pad;
#pragma GCC unroll 8
    for (int j = 0; j < NC; ++j) {
      float sum = sums[(o * NC + j) / kLanes][(o * NC + j) % kLanes];
      for (int p = k_vec; p < k; ++p) sum += a_row[p] * b[j * bcs + p];
      if (epilogue.row_bias != nullptr) sum += epilogue.row_bias[o];
      if (epilogue.col_bias != nullptr) sum += epilogue.col_bias[j];
      const int64_t at_c = o * crs + j * ccs;
      if (accumulate) sum += c[at_c];
      c[at_c] = Activate(sum, epilogue.relu, mask != nullptr ? mask + at_c : nullptr);
    }
  }
}

// The epilogue of the columns from j on (the mask is offset by the caller).
inline Epilogue ShiftColumns(Epilogue e, int j) {
  if (e.col_bias != nullptr) e.col_bias += j;
  return e;
}

template <int M>
void SmallMGemm(const ConstView& a, const ConstView& b, const MutView& c, bool accumulate,
                const Epilogue& epilogue, Vector* workspace) {
  const int n = c.cols;
  const int k = a.cols;
  const int k_pad = (k + kLanes - 1) / kLanes * kLanes;
  const int64_t needed = static_cast<int64_t>(M) * k_pad;
  if (workspace->size() < needed) workspace->resize(needed);
  float* at = workspace->data();
  for (int o = 0; o < M; ++o) {
    float* row = at + static_cast<int64_t>(o) * k_pad;
    for (int p = 0; p < k; ++p) row[p] = a.data[o * a.row_stride + p * a.col_stride];
    std::fill(row + k, row + k_pad, 0.0f);
  }
  auto mask_at = [&](int j) {
    return epilogue.mask != nullptr ? epilogue.mask + j * c.col_stride : nullptr;
  };
  int j = 0;
  for (; j + kDotColumns <= n; j += kDotColumns) {
    DotKernel<M, kDotColumns>(k, k_pad, at, b.data + j * b.col_stride, b.col_stride,
                              ShiftColumns(epilogue, j), accumulate, c.data + j * c.col_stride,
                              mask_at(j), c.row_stride, c.col_stride);
  }
  for (; j < n; ++j) {
    DotKernel<M, 1>(k, k_pad, at, b.data + j * b.col_stride, b.col_stride,
                    ShiftColumns(epilogue, j), accumulate, c.data + j * c.col_stride, mask_at(j),
                    c.row_stride, c.col_stride);
  }
}

// Gemm() on the calling thread alone.
void GemmOneThread(const ConstView& a, const ConstView& b, const MutView& c, bool accumulate,
                   const Epilogue& epilogue, Vector* workspace) {
  const int m = c.rows;
  const int n = c.cols;
  const int k = a.cols;
  if (m == 0 || n == 0) return;
  // Panels of fewer rows than a vector waste most of each multiply. For a few rows, use dot
  // products if the columns of B are contiguous...
  if (k > 0 && m <= kMaxSmallM && b.row_stride == 1) {
    switch (m) {
      case 1:
        return SmallMGemm<1>(a, b, c, accumulate, epilogue, workspace);
      case 2:
        return SmallMGemm<2>(a, b, c, accumulate, epilogue, workspace);
      case 3:
        return SmallMGemm<3>(a, b, c, accumulate, epilogue, workspace);
      default:
        return SmallMGemm<4>(a, b, c, accumulate, epilogue, workspace);
    }
  }
  if (k > 0 && !(m < kLanes && n > m)) return PanelGemm(a, b, c, accumulate, epilogue, workspace);

  // ... otherwise (and for an empty product) add the bias first, then the product as
  // C^T += B^T A^T, which has n rows, then apply the activation steps.
  auto elem = [&](int i, int j) { return i * c.row_stride + j * c.col_stride; };
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < m; ++i) {
      float bias = epilogue.row_bias != nullptr ? epilogue.row_bias[i] : 0.0f;
      if (epilogue.col_bias != nullptr) bias += epilogue.col_bias[j];
      c.data[elem(i, j)] = accumulate ? c.data[elem(i, j)] + bias : bias;
    }
  }
  if (k > 0) {
    PanelGemm(b.Transposed(), a.Transposed(), c.Transposed(), /*accumulate=*/true, Epilogue{},
              workspace);
  }
  if (epilogue.relu || epilogue.mask != nullptr) {
    for (int j = 0; j < n; ++j) {
      for (int i = 0; i < m; ++i) {
        const float* mask = epilogue.mask != nullptr ? epilogue.mask + elem(i, j) : nullptr;
        c.data[elem(i, j)] = Activate(c.data[elem(i, j)], epilogue.relu, mask);
      }
    }
  }
}

}  // namespace

void AddRowSums(const float* data, int rows, int cols, float* out) {
  // Blocks of kRowVecs vectors of rows: add the columns one after another into registers.
  constexpr int kRowVecs = 8;
  constexpr int kBlock = kRowVecs * kLanes;
  int i0 = 0;
  for (; i0 + kBlock <= rows; i0 += kBlock) {
    Vec acc[kRowVecs];
#pragma GCC unroll 8
    for (int v = 0; v < kRowVecs; ++v) acc[v] = Load(out + i0 + v * kLanes);
    for (int j = 0; j < cols; ++j) {
      const float* col = data + static_cast<int64_t>(j) * rows + i0;
#pragma GCC unroll 8
      for (int v = 0; v < kRowVecs; ++v) acc[v] += Load(col + v * kLanes);
    }
#pragma GCC unroll 8
    for (int v = 0; v < kRowVecs; ++v) Store(out + i0 + v * kLanes, acc[v]);
  }
  for (; i0 + kLanes <= rows; i0 += kLanes) {
    Vec acc = Load(out + i0);
    for (int j = 0; j < cols; ++j) acc += Load(data + static_cast<int64_t>(j) * rows + i0);
    Store(out + i0, acc);
  }
  for (; i0 < rows; ++i0) {
    float sum = 0.0f;
    for (int j = 0; j < cols; ++j) sum += data[static_cast<int64_t>(j) * rows + i0];
    out[i0] += sum;
  }
}

void GemmOne(const ConstView& a, const ConstView& b, const MutView& c, bool accumulate,
             const Epilogue& epilogue, Vector* workspace) {
  GemmOneThread(a, b, c, accumulate, epilogue, workspace);
}

void GemmPackedOne(const float* a_packed, int m, int k, const ConstView& b, const MutView& c,
                   bool accumulate, const Epilogue& epilogue, Vector* workspace) {
  PanelGemm({nullptr, m, k, 0, 0}, b, c, accumulate, epilogue, workspace, a_packed);
}

}  // namespace rl::nn::internal::RL_NN_ISA
