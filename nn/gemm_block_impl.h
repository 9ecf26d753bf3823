// What the fp32 and the bf16 micro-kernels share: the block of the result they compute, and how
// its accumulators start (bias) and are stored (accumulation, ReLU, mask). Included by the
// kernels_*.cc files only, inside the namespace of their instruction set (RL_NN_ISA).
#ifndef RL_NN_ISA
#error "nn/gemm_block_impl.h is included by the kernels_*.cc files only"
#endif

namespace rl::nn::internal::RL_NN_ISA {
namespace {

template <class V>
inline V LoadVec(const float* p) {
  V v;
  std::memcpy(&v, p, sizeof(v));
  return v;
}
template <class V>
inline void StoreVec(float* p, V v) {
  std::memcpy(p, &v, sizeof(v));
}

// The activation steps of an Epilogue for one element; `mask` points at the element's mask entry.
inline float Activate(float r, bool relu, const float* mask) {
  if (relu) r = std::max(r, 0.0f);
  if (mask != nullptr && !(*mask > 0.0f)) r = 0.0f;
  return r;
}

// What one micro-kernel call computes and where it stores it.
struct Block {
  const float* bias;      // V * lanes floats (padded) or null.
  const float* col_bias;  // NR floats or null: added to column j of the block.
  bool accumulate;
  bool relu;
  const float* mask;  // Laid out like c, or null.
  float* c;
  int64_t crs;
  int64_t ccs;
  int rows;  // Rows of the result to store, <= V * lanes.
};

// The block of the rows [i0, i0 + rows) of c that a slice of the shared dimension computes: only
// the first slice may overwrite c or add the bias (copied into `bias_panel`, padded with zeros to
// `mr` rows), only the last one applies the activation steps; `mask_rows` gets the mask's rows
// (null without one). The columns (c, col_bias, mask) are set per call.
inline Block PanelBlock(const MutView& c, int i0, int rows, int mr, bool first, bool last,
                        bool accumulate, const Epilogue& epilogue, float* bias_panel,
                        const float** mask_rows) {
  Block out{nullptr,
            nullptr,
            accumulate || !first,
            last && epilogue.relu,
            nullptr,
            c.data + i0 * c.row_stride,
            c.row_stride,
            c.col_stride,
            rows};
  if (first && epilogue.row_bias != nullptr) {
    std::copy(epilogue.row_bias + i0, epilogue.row_bias + i0 + rows, bias_panel);
    std::fill(bias_panel + rows, bias_panel + mr, 0.0f);
    out.bias = bias_panel;
  }
  *mask_rows = last && epilogue.mask != nullptr ? epilogue.mask + i0 * c.row_stride : nullptr;
  return out;
}

// The accumulators of a V x NR block of vectors of L floats: the bias of their rows plus the bias
// of their column, or 0.
template <class Vec, int L, int V, int NR>
inline void InitAccumulators(const Block& out, Vec (&acc)[V][NR]) {
#pragma GCC unroll 8
  for (int i = 0; i < V; ++i) {
    const Vec init = out.bias != nullptr ? LoadVec<Vec>(out.bias + i * L) : Vec{};
#pragma GCC unroll 16
    for (int j = 0; j < NR; ++j) {
      acc[i][j] = out.col_bias != nullptr ? init + out.col_bias[j] : init;
    }
  }
}

// Stores the accumulators into the block (=|+=), then the activation steps. Whole vectors when
// the block is full and contiguous, element-wise otherwise.
template <class Vec, int L, int V, int NR>
inline void StoreAccumulators(const Vec (&acc)[V][NR], const Block& out) {
  constexpr int kMr = V * L;
  if (out.crs == 1 && out.rows == kMr) {
#pragma GCC unroll 16
    for (int j = 0; j < NR; ++j) {
#pragma GCC unroll 8
      for (int i = 0; i < V; ++i) {
        float* cp = out.c + j * out.ccs + i * L;
        Vec r = out.accumulate ? LoadVec<Vec>(cp) + acc[i][j] : acc[i][j];
        if (out.relu) r = r > Vec{} ? r : Vec{};
        if (out.mask != nullptr) {
          r = LoadVec<Vec>(out.mask + j * out.ccs + i * L) > Vec{} ? r : Vec{};
        }
        StoreVec(cp, r);
      }
    }
    return;
  }
  alignas(64) float tmp[NR][kMr];
#pragma GCC unroll 16
  for (int j = 0; j < NR; ++j) {
#pragma GCC unroll 8
    for (int i = 0; i < V; ++i) StoreVec(&tmp[j][i * L], acc[i][j]);
  }
  for (int j = 0; j < NR; ++j) {
    for (int i = 0; i < out.rows; ++i) {
      const int64_t at = i * out.crs + j * out.ccs;
      const float r = out.accumulate ? out.c[at] + tmp[j][i] : tmp[j][i];
      out.c[at] = Activate(r, out.relu, out.mask != nullptr ? out.mask + at : nullptr);
    }
  }
}

}  // namespace
}  // namespace rl::nn::internal::RL_NN_ISA
