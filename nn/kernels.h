// The kernel paths: one set of kernels per instruction set, each compiled for its instruction
// set alone (kernels_avx2.cc, kernels_avx512.cc, kernels_avx512_bf16.cc) while the rest of the
// library targets the build's baseline (x86-64-v3), and the one in use picked at run time from
// the CPU's features (nn/precision.h). Not part of the public API.
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "nn/tensor.h"

namespace rl::nn::internal {

struct ConstView;
struct MutView;
struct Epilogue;

/// The shape of a convolution as its kernels see it (see Conv2d in nn/conv2d.h): the input split
/// into stride x stride phase planes of the zero-padded input, plane_h x plane_w each, so that
/// every unfolding copy is a contiguous run.
struct ConvGeometry {
  int in_channels = 0;
  int kernel = 0;
  int stride = 0;
  int out_h = 0;
  int out_w = 0;
  int pixels = 0;  // out_h * out_w
  int taps = 0;    // in_channels * kernel * kernel
  int plane_h = 0;
  int plane_w = 0;
  int64_t plane_stride = 0;  // floats per sample in the planes
  // Plane floats from the first to the last pixel of one output window and, when that is at
  // most 16, where each output pixel of the window is among them.
  int window_span = 0;
  std::array<int32_t, 16> window_index{};
  // Per tap (c, ky, kx): where its pixel for output pixel (0, 0) lies in a sample's planes.
  std::vector<int64_t> tap_offset;
};

/// A run of consecutive output pixels of one sample within a panel of the unfolded matrix (rows
/// (sample, oy, ox)): a run of consecutive plane pixels, which every tap copies from its own plane
/// and offset (ConvGeometry::tap_offset).
struct PanelPiece {
  int64_t src;  // Offset of its first pixel in the planes of the group (for tap offset 0).
  int lane;     // First row of the panel it fills.
  int n;        // Pixels.
};

/// The pieces of panel q of the unfolded group of m rows, rows [q R, min(m, (q + 1) R)) with
/// R = panel_rows, into `pieces` (room for R); returns how many there are.
inline int PanelPieces(const ConvGeometry& g, int64_t q, int panel_rows, int64_t m,
                       PanelPiece* pieces) {
  int n_pieces = 0;
  const int64_t r_end = std::min(m, (q + 1) * panel_rows);
  for (int64_t r = q * panel_rows; r < r_end;) {
    const int64_t t = r / g.pixels;
    const int oy = static_cast<int>(r % g.pixels) / g.out_w;
    const int ox = static_cast<int>(r % g.pixels) % g.out_w;
    const int n = static_cast<int>(std::min<int64_t>(g.out_w - ox, r_end - r));
    pieces[n_pieces++] = {t * g.plane_stride + static_cast<int64_t>(oy) * g.plane_w + ox,
                          static_cast<int>(r - q * panel_rows), n};
    r += n;
  }
  return n_pieces;
}

/// A block of the unfolded gradient that adds up into a phase plane, shifted by (dy, dx) (see
/// Conv2d::PlaneGradient()).
struct GradientRun {
  const float* src;
  int dy;
  int dx;
};

/// c = a * b (+=, epilogue) on the calling thread (see Gemm() in nn/gemm.h).
using GemmFn = void (*)(const ConstView& a, const ConstView& b, const MutView& c, bool accumulate,
                        const Epilogue& epilogue, Vector* workspace);
/// The same for an m x k left operand packed in panels (see GemmPacked() in nn/gemm.h).
using GemmPackedFn = void (*)(const float* a_packed, int m, int k, const ConstView& b,
                              const MutView& c, bool accumulate, const Epilogue& epilogue,
                              Vector* workspace);
/// The same for one packed in bf16 pairs (see GemmPackedPairs() in nn/gemm.h).
using GemmPairsFn = void (*)(const uint32_t* a_pairs, int m, int k, const ConstView& b,
                             const MutView& c, bool accumulate, const Epilogue& epilogue,
                             Vector* workspace);

/// The kernels of one path.
struct KernelSet {
  const char* name;
  // fp32 products: rows per packed panel of the left operand and result columns per
  // micro-kernel call (how a product is split over threads), and the products themselves.
  int panel_rows;
  int nr;
  GemmFn gemm;
  GemmPackedFn gemm_packed;
  // bf16 products on the CPU's instructions, with their panel rows and columns; null (and 0)
  // where bf16 is emulated.
  int bf16_panel_rows;
  int bf16_nr;
  GemmFn gemm_bf16;
  GemmPackedFn gemm_packed_bf16;
  GemmPairsFn gemm_pairs_bf16;
  // Im2col in the bf16 pairs of GemmPackedPairs() (nn/gemm.h), `count` samples.
  void (*im2col_pairs)(const ConvGeometry& g, const float* planes, int count, uint32_t* pairs);
  // Rows [i0, i0 + rows) of `a` (i0 a multiple of bf16_panel_rows) in the bf16 pairs of
  // GemmPackedPairs(), from the first word of panel i0 / bf16_panel_rows on.
  void (*round_into_pairs)(const ConstView& a, int i0, int rows, uint32_t* pairs);
  // Outputs [i_begin, i_end) of Gemv() (nn/gemv.h), i_begin a multiple of 128.
  void (*gemv_rows)(const float* w, int out, int in, const float* x, const float* b, bool relu,
                    float* y, int i_begin, int i_end);
  // out[i] += sum_j g[i + j * rows].
  void (*add_row_sums)(const float* g, int rows, int cols, float* out);
  // `runs` runs of `len` floats: dst[r * dst_step, + len) = src[r * src_step, + len).
  void (*copy_runs)(const float* src, int64_t src_step, float* dst, int64_t dst_step, int runs,
                    int len);
  // Splits the row `src` of n * s floats, of which the first `valid` are read and the rest taken
  // as 0, into s rows of n: dst[px * plane_size + x] = src[x * s + px].
  void (*deinterleave)(const float* src, int valid, int s, int n, int64_t plane_size, float* dst);
  // The inverse: dst[x * s + px] = src[px * plane_size + x].
  void (*interleave)(const float* src, int s, int n, int64_t plane_size, float* dst);
  // Unfolds `count` samples whose planes start at `planes` into `cols`, (count * pixels) x taps,
  // column-major.
  void (*im2col)(const ConvGeometry& g, const float* planes, int count, float* cols);
  // The same in the packed panel layout of GemmPacked() with panels of `panel_rows` rows.
  void (*im2col_panels)(const ConvGeometry& g, const float* planes, int count, int panel_rows,
                        float* cols);
  // Writes plane_h x plane_w floats (row-major) into `out`: the sum of the runs.
  void (*plane_gradient)(const ConvGeometry& g, const GradientRun* runs, int n_runs, float* out);
};

/// The set in use (see KernelPath() in nn/precision.h). Throws std::runtime_error the first time
/// when RL_KERNELS asks for a path that cannot run.
const KernelSet& Kernels();

/// The paths' sets, each defined in its own translation unit.
KernelSet Avx2Kernels();
KernelSet Avx512Kernels();
/// The avx512 set with the bf16 products of kernels_avx512_bf16.cc.
KernelSet Avx512Bf16Kernels();

}  // namespace rl::nn::internal
