// The unfolding's gather on AVX-512, shared by the fp32 panels (conv_impl.h's Im2colPanels()) and
// the bf16 pairs (gemm_bf16_impl.h's Im2colPairs()): a panel row of one tap (panel_rows
// consecutive rows of the unfolded matrix) is read in 16-float vectors, each merged in a register
// from masked loads of the pieces that reach into it (PanelPieces() in nn/kernels.h), and stored
// whole. The pieces are cut into loads once per panel; every tap then uses them at its own offset.
// Masked-off lanes are not read, so no load reaches past the planes. Included by the kernels_*.cc
// files only, inside the namespace of their instruction set (RL_NN_ISA), where RL_NN_AVX512 is 1.
#if !defined(RL_NN_ISA) || !RL_NN_AVX512
#error "nn/panel_gather_impl.h is included by the AVX-512 kernels_*.cc files only"
#endif

namespace rl::nn::internal::RL_NN_ISA {
namespace {

// One load into a vector of a panel row: lanes `mask` read the planes at src + lane (for tap
// offset 0).
struct PanelLoad {
  int64_t src;
  __mmask16 mask;
};

// A piece covers at least one row, so a vector takes at most 16 loads.
constexpr int kMaxLoadsPerVector = 16;

// Cuts the `n_pieces` pieces of a panel into the loads of its `vectors` vectors: those of vector
// v are loads[first[v], first[v + 1]) (room for vectors * kMaxLoadsPerVector loads and vectors + 1
// firsts).
inline void PlanPanelLoads(const PanelPiece* pieces, int n_pieces, int vectors, PanelLoad* loads,
                           int* first) {
  int n_loads = 0;
  for (int v = 0; v < vectors; ++v) {
    first[v] = n_loads;
    const int lo = v * 16;
    for (int i = 0; i < n_pieces; ++i) {
      const PanelPiece& piece = pieces[i];
      const int a = std::max(lo, piece.lane);
      const int b = std::min(lo + 16, piece.lane + piece.n);
      if (a >= b) continue;
      const auto mask = static_cast<__mmask16>(((1U << (b - a)) - 1U) << (a - lo));
      loads[n_loads++] = {piece.src - piece.lane + lo, mask};
    }
  }
  first[vectors] = n_loads;
}

// A vector from the loads [0, N), zero in the lanes none of them fills.
template <int N>
inline __m512 GatherVector(const PanelLoad* loads, const float* tap_planes) {
  __m512 v = _mm512_maskz_loadu_ps(loads[0].mask, tap_planes + loads[0].src);
#pragma GCC unroll 4
  for (int i = 1; i < N; ++i) v = _mm512_mask_loadu_ps(v, loads[i].mask, tap_planes + loads[i].src);
  return v;
}

// The loads of one vector in a plan of PlanPanelLoads(): loads[first[v], first[v + 1]).
struct VectorLoads {
  const PanelLoad* loads;
  int n;
};

inline VectorLoads LoadsOfVector(const PanelLoad* loads, const int* first, int v) {
  return {loads + first[v], first[v + 1] - first[v]};
}

// A vector from any number of loads, the common counts unrolled.
inline __m512 GatherVector(const VectorLoads& vector, const float* tap_planes) {
  const PanelLoad* loads = vector.loads;
  switch (vector.n) {
    case 0:
      return _mm512_setzero_ps();
    case 1:
      return loads[0].mask == 0xFFFFU ? _mm512_loadu_ps(tap_planes + loads[0].src)
                                      : GatherVector<1>(loads, tap_planes);
    case 2:
      return GatherVector<2>(loads, tap_planes);
    case 3:
      return GatherVector<3>(loads, tap_planes);
    default: {
      __m512 v = GatherVector<4>(loads, tap_planes);
      for (int i = 4; i < vector.n; ++i) {
        v = _mm512_mask_loadu_ps(v, loads[i].mask, tap_planes + loads[i].src);
      }
      return v;
    }
  }
}

}  // namespace
}  // namespace rl::nn::internal::RL_NN_ISA
