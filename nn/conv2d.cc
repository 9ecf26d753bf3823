#include "nn/conv2d.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <string>

#ifdef __AVX512F__
#include <immintrin.h>
#endif

#include "common/check.h"
#include "nn/gemm.h"
#include "nn/init.h"
#include "nn/parallel.h"

namespace rl::nn {
namespace {

// Floats of unfolded input per group: the group is as many samples as fit, so that the unfolded
// matrix (about 512 KB) stays in the L2 cache while the kernel reads it.
constexpr int64_t kColsBudget = 128 * 1024;

// dst[0, n) = src[0, n).
inline void CopyRun(const float* src, int n, float* dst) {
#ifdef __AVX512F__
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

// Splits the row `src` of n * s floats, of which the first `valid` are read and the rest taken
// as 0, into s rows of n: dst[px * plane_size + x] = src[x * s + px]. Unrolled for the common
// strides so that the compiler vectorises it, and with AVX-512 permutes for strides 2 and 4 (the
// Nature network's).
template <int S>
void DeinterleaveFixed(const float* __restrict src, int valid, int n, int64_t plane_size,
                       float* __restrict dst) {
#ifdef __AVX512F__
  if constexpr (S == 2 || S == 4) {
    // Output px takes lanes px, px + S, ... of 16 S consecutive inputs: for S = 2 one two-source
    // permute; for S = 4 eight lanes from each half of them, then the halves joined. Loads stop
    // at `valid` (masked lanes read as 0) and the last chunk stores only the lanes it has.
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
        const int lanes = std::clamp(floats - 16 * i, 0, 16);
        const auto mask = static_cast<__mmask16>((1U << lanes) - 1U);
        v[i] = _mm512_maskz_loadu_ps(mask, src + S * x0 + 16 * i);
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
        _mm512_mask_storeu_ps(dst + px * plane_size + x0, out_mask, out);
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
#ifdef __AVX512F__
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

std::string ConvName(int in_channels, int out_channels, int kernel, int stride, int padding,
                     int in_h, int in_w) {
  return "conv2d(" + std::to_string(in_channels) + "," + std::to_string(out_channels) + "," +
         std::to_string(kernel) + "," + std::to_string(stride) + "," + std::to_string(padding) +
         "," + std::to_string(in_h) + "," + std::to_string(in_w) + ")";
}

}  // namespace

Conv2d::Conv2d(int in_channels, int out_channels, int kernel, int stride, int padding, int in_h,
               int in_w, std::mt19937* rng)
    : in_{in_channels, in_h, in_w}, kernel_(kernel), stride_(stride), padding_(padding) {
  const std::string name = ConvName(in_channels, out_channels, kernel, stride, padding, in_h, in_w);
  if (in_channels <= 0 || out_channels <= 0 || kernel <= 0 || stride <= 0 || in_h <= 0 ||
      in_w <= 0 || padding < 0) {
    throw std::invalid_argument(name + ": sizes, kernel and stride must be positive and padding " +
                                "non-negative");
  }
  if (kernel > in_h + 2 * padding || kernel > in_w + 2 * padding) {
    throw std::invalid_argument(name + ": the kernel is larger than the padded input");
  }
  RL_CHECK(rng != nullptr) << "Conv2d needs a random generator";
  out_ = {out_channels, (in_h + 2 * padding - kernel) / stride + 1,
          (in_w + 2 * padding - kernel) / stride + 1};
  taps_ = in_channels * kernel * kernel;
  pixels_ = out_.height * out_.width;
  direct_ = stride == 1 && padding == 0;
  dense_ = padding == 0 && kernel == in_h && kernel == in_w;
  if (direct_) {
    plane_h_ = in_h;
    plane_w_ = in_w;
    plane_stride_ = in_.size();
  } else {
    plane_h_ = (in_h + 2 * padding + stride - 1) / stride;
    plane_w_ = (in_w + 2 * padding + stride - 1) / stride;
    plane_stride_ = static_cast<int64_t>(in_channels) * stride * stride * plane_h_ * plane_w_;
  }

  window_span_ = (out_.height - 1) * plane_w_ + out_.width;
  if (window_span_ <= 16) {
    for (int i = 0; i < 16; ++i) {
      window_index_[i] = i < pixels_ ? (i / out_.width) * plane_w_ + i % out_.width : 0;
    }
  }
  tap_offset_.resize(taps_);
  for (int c = 0; c < in_channels; ++c) {
    for (int ky = 0; ky < kernel; ++ky) {
      for (int kx = 0; kx < kernel; ++kx) {
        const int64_t plane =
            (static_cast<int64_t>(c) * stride + ky % stride) * stride + kx % stride;
        tap_offset_[(c * kernel + ky) * kernel + kx] =
            plane * plane_h_ * plane_w_ + static_cast<int64_t>(ky / stride) * plane_w_ +
            kx / stride;
      }
    }
  }
  dcols_front_ = (kernel + 15) / 16 * 16;
  scratch_.resize(1);

  weight_.resize(taps_, out_channels);
  bias_.resize(out_channels, 1);
  const float bound = 1.0f / std::sqrt(static_cast<float>(taps_));
  FillUniform(bound, rng, &weight_);
  FillUniform(bound, rng, &bias_);
  weight_grad_.setZero(taps_, out_channels);
  bias_grad_.setZero(out_channels, 1);
}

int Conv2d::GroupSize(int batch) const {
  const int64_t per_sample = static_cast<int64_t>(pixels_) * taps_;
  return static_cast<int>(std::clamp<int64_t>(kColsBudget / per_sample, 1, std::max(batch, 1)));
}

void Conv2d::BuildPlanes(const Matrix& x, int b0, int count, Scratch* scratch) const {
  if (direct_) return;
  const int s = stride_;
  const int p = padding_;
  const int h = in_.height;
  const int w = in_.width;
  const int row_len = plane_w_ * s;  // A padded input row, extended to whole plane columns.
  const int64_t plane_size = static_cast<int64_t>(plane_h_) * plane_w_;
  if (scratch->planes.size() < plane_stride_ * count) scratch->planes.resize(plane_stride_ * count);
  if (scratch->padded_row.size() < row_len) scratch->padded_row.resize(row_len);
  // Plane (c, py, px) holds the pixels (Y * s + py, X * s + px) of the zero-padded channel c:
  // padded row Y * s + py is split into the s planes (c, py, .) at row Y. Without padding on the
  // left, input rows are split in place (the split reads zeros past their end); otherwise through
  // a zero-padded copy.
  for (int t = 0; t < count; ++t) {
    const float* image = x.col(b0 + t).data();
    float* sample_planes = scratch->planes.data() + t * plane_stride_;
    for (int c = 0; c < in_.channels; ++c) {
      const float* channel = image + static_cast<int64_t>(c) * h * w;
      for (int yp = 0; yp < plane_h_ * s; ++yp) {
        float* dst = sample_planes + (static_cast<int64_t>(c) * s + yp % s) * s * plane_size +
                     static_cast<int64_t>(yp / s) * plane_w_;
        const int iy = yp - p;
        if (iy < 0 || iy >= h) {
          for (int px = 0; px < s; ++px) {
            std::fill(dst + px * plane_size, dst + px * plane_size + plane_w_, 0.0f);
          }
          continue;
        }
        const float* row = channel + static_cast<int64_t>(iy) * w;
        if (p == 0) {
          Deinterleave(row, w, s, plane_w_, plane_size, dst);
          continue;
        }
        // The padding is rewritten every time: Backward() reuses this row.
        float* padded = scratch->padded_row.data();
        std::fill(padded, padded + p, 0.0f);
        std::copy(row, row + w, padded + p);
        std::fill(padded + p + w, padded + row_len, 0.0f);
        Deinterleave(padded, row_len, s, plane_w_, plane_size, dst);
      }
    }
  }
}

const float* Conv2d::GroupPlanes(const Matrix& x, int b0, const Scratch& scratch) const {
  return direct_ ? x.col(b0).data() : scratch.planes.data();
}

void Conv2d::Im2col(const float* planes, int count, bool panels, Scratch* scratch) const {
  const int s = stride_;
  const int k = kernel_;
  const int oh = out_.height;
  const int ow = out_.width;
  const int64_t m = static_cast<int64_t>(count) * pixels_;
  const int64_t plane_size = static_cast<int64_t>(plane_h_) * plane_w_;
  if (panels) return Im2colPanels(planes, count, scratch);
  if (scratch->cols.size() < m * taps_) scratch->cols.resize(m * taps_);
  // Column (c, ky, kx) of the unfolded matrix, row (sample, oy, ox), holds the padded input pixel
  // (oy * s + ky, ox * s + kx) of channel c: pixel (oy + ky / s, ox + kx / s) of phase plane
  // (c, ky % s, kx % s). For each output row that is a contiguous run of ow plane pixels.
  for (int c = 0; c < in_.channels; ++c) {
    for (int ky = 0; ky < k; ++ky) {
      for (int kx = 0; kx < k; ++kx) {
        const int64_t tap = (static_cast<int64_t>(c) * k + ky) * k + kx;
        const int64_t plane = (static_cast<int64_t>(c) * s + ky % s) * s + kx % s;
        const float* src0 =
            planes + plane * plane_size + static_cast<int64_t>(ky / s) * plane_w_ + kx / s;
        float* dst = scratch->cols.data() + tap * m;
#ifdef __AVX512F__
        if (window_span_ <= 16) {
          // The whole oh x ow window lies within 16 consecutive plane floats: one load, one
          // permute and one store per sample.
          const auto load_mask = static_cast<__mmask16>((1U << window_span_) - 1U);
          const auto store_mask = static_cast<__mmask16>((1U << pixels_) - 1U);
          const __m512i window = _mm512_loadu_si512(window_index_.data());
          for (int t = 0; t < count; ++t) {
            const __m512 v = _mm512_maskz_loadu_ps(load_mask, src0 + t * plane_stride_);
            _mm512_mask_storeu_ps(dst, store_mask, _mm512_permutexvar_ps(window, v));
            dst += pixels_;
          }
          continue;
        }
#endif
        for (int t = 0; t < count; ++t) {
          const float* src = src0 + t * plane_stride_;
          if (plane_w_ == ow) {
            CopyRun(src, oh * ow, dst);
            dst += static_cast<int64_t>(oh) * ow;
            continue;
          }
          for (int oy = 0; oy < oh; ++oy) {
            CopyRun(src + static_cast<int64_t>(oy) * plane_w_, ow, dst);
            dst += ow;
          }
        }
      }
    }
  }
}

void Conv2d::Im2colPanels(const float* planes, int count, Scratch* scratch) const {
  using internal::kPanelRows;
  const int ow = out_.width;
  const int64_t m = static_cast<int64_t>(count) * pixels_;
  const int64_t panels = (m + kPanelRows - 1) / kPanelRows;
  if (scratch->cols.size() < panels * kPanelRows * taps_) {
    scratch->cols.setZero(panels * kPanelRows * taps_);
  }
  // Panel by panel, so that the writes are sequential: the panel's rows (sample, oy, ox) fall
  // into a few runs of consecutive ox, each a run of consecutive plane pixels, which every tap
  // copies from its own plane and offset (tap_offset_).
  struct Piece {
    int64_t src;  // Offset of the first pixel in the planes of the group (for tap offset 0).
    int lane;     // First row of the panel it fills.
    int n;
  };
  std::array<Piece, internal::kPanelRows> pieces{};
  for (int64_t q = 0; q < panels; ++q) {
    int n_pieces = 0;
    const int64_t r_end = std::min(m, (q + 1) * kPanelRows);
    for (int64_t r = q * kPanelRows; r < r_end;) {
      const int64_t t = r / pixels_;
      const int oy = static_cast<int>(r % pixels_) / ow;
      const int ox = static_cast<int>(r % pixels_) % ow;
      const int n = static_cast<int>(std::min<int64_t>(ow - ox, r_end - r));
      pieces[n_pieces++] = {t * plane_stride_ + static_cast<int64_t>(oy) * plane_w_ + ox,
                            static_cast<int>(r - q * kPanelRows), n};
      r += n;
    }
    float* dst = scratch->cols.data() + q * kPanelRows * taps_;
    for (int tap = 0; tap < taps_; ++tap, dst += kPanelRows) {
      const float* src = planes + tap_offset_[tap];
      for (int i = 0; i < n_pieces; ++i) {
        CopyRun(src + pieces[i].src, pieces[i].n, dst + pieces[i].lane);
      }
    }
  }
}

void Conv2d::PlaneGradient(const float* dcols, int count, int t, int c, int py, int px, float* out,
                           Scratch* scratch) const {
  const int s = stride_;
  const int k = kernel_;
  const int oh = out_.height;
  const int ow = out_.width;
  const int n = plane_w_;
  const int64_t m = static_cast<int64_t>(count) * pixels_;
  // Pixel (Y, X) of phase plane (c, py, px) was copied by Im2col() into column (c, ky, kx),
  // ky = KY * s + py, kx = KX * s + px, at output pixel (Y - KY, X - KX). Each (KY, KX) adds a
  // block of oh x ow entries of that column, shifted by (KY, KX), to the plane.
  int n_runs = 0;
  for (int ky = py, ky_step = 0; ky < k; ky += s, ++ky_step) {
    for (int kx = px, kx_step = 0; kx < k; kx += s, ++kx_step) {
      const int64_t tap = (static_cast<int64_t>(c) * k + ky) * k + kx;
      scratch->runs[n_runs] = {dcols + tap * m + static_cast<int64_t>(t) * pixels_, ky_step,
                               kx_step};
      ++n_runs;
    }
  }
  for (int y = 0; y < plane_h_; ++y) {
    float* row = out + static_cast<int64_t>(y) * n;
#ifdef __AVX512F__
    for (int x0 = 0; x0 < n; x0 += 16) {
      __m512 acc = _mm512_setzero_ps();
      for (int r = 0; r < n_runs; ++r) {
        const Run& run = scratch->runs[r];
        const int oy = y - run.dy;
        // Lanes x0 + l with 0 <= x0 + l - dx < ow. dcols has dcols_front_ >= kernel_ floats of
        // slack in front, so the address below stays inside the buffer.
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
      const Run& run = scratch->runs[r];
      const int oy = y - run.dy;
      if (oy < 0 || oy >= oh) continue;
      const float* src = run.src + static_cast<int64_t>(oy) * ow;
      const int hi = std::min(n, run.dx + ow);
      for (int xx = run.dx; xx < hi; ++xx) row[xx] += src[xx - run.dx];
    }
#endif
  }
}

void Conv2d::FoldGradient(const Matrix& x, int b0, int count, Scratch* scratch) {
  const int s = stride_;
  const int p = padding_;
  const int h = in_.height;
  const int w = in_.width;
  const int64_t plane_size = static_cast<int64_t>(plane_h_) * plane_w_;
  const float* dcols = scratch->dcols.data() + dcols_front_;
  const auto steps = static_cast<size_t>((kernel_ + s - 1) / s);
  if (scratch->runs.size() < steps * steps) scratch->runs.resize(steps * steps);
  if (!direct_ && scratch->channel_grad.size() < s * s * plane_size) {
    scratch->channel_grad.resize(s * s * plane_size);
  }
  for (int t = 0; t < count; ++t) {
    const float* image = x.col(b0 + t).data();
    float* dx_image = grad_input_.col(b0 + t).data();
    for (int c = 0; c < in_.channels; ++c) {
      const int64_t at = static_cast<int64_t>(c) * h * w;
      if (direct_) {
        // The input channel is its own phase plane.
        PlaneGradient(dcols, count, t, c, 0, 0, dx_image + at, scratch);
      } else {
        // The s * s phase planes of the padded channel, then interleaved into d(loss)/d(x):
        // input pixel (iy, ix) is pixel ((iy + p) / s, (ix + p) / s) of plane
        // ((iy + p) % s, (ix + p) % s).
        float* planes = scratch->channel_grad.data();
        for (int py = 0; py < s; ++py) {
          for (int px = 0; px < s; ++px) {
            PlaneGradient(dcols, count, t, c, py, px, planes + (py * s + px) * plane_size, scratch);
          }
        }
        for (int iy = 0; iy < h; ++iy) {
          const int yp = iy + p;
          const float* rows =
              planes + static_cast<int64_t>(yp % s) * s * plane_size + (yp / s) * plane_w_;
          float* dst = dx_image + at + static_cast<int64_t>(iy) * w;
          if (p == 0 && plane_w_ * s == w) {
            Interleave(rows, s, plane_w_, plane_size, dst);
            continue;
          }
          for (int px = 0; px < s; ++px) {
            // Plane column X holds input column X * s + px - p.
            const float* src = rows + px * plane_size;
            const int x_lo = std::max(0, (p - px + s - 1) / s);
            const int x_hi = std::min(plane_w_, (w + p - px + s - 1) / s);
            for (int xx = x_lo; xx < x_hi; ++xx) dst[xx * s + px - p] = src[xx];
          }
        }
      }
      if (fused_input_relu_grad_) {
        // The backward pass of a preceding ReLU: zero where its output, our input, is not
        // positive.
        const float* xs = image + at;
        float* dst = dx_image + at;
        for (int64_t i = 0; i < static_cast<int64_t>(h) * w; ++i) {
          dst[i] = xs[i] > 0.0f ? dst[i] : 0.0f;
        }
      }
    }
  }
}

int Conv2d::PrepareTasks(int batch) {
  const int64_t work = static_cast<int64_t>(batch) * pixels_ * taps_ * out_.channels;
  const int tasks = internal::TasksFor(work, batch);
  if (static_cast<int>(scratch_.size()) < tasks) scratch_.resize(static_cast<size_t>(tasks));
  return tasks;
}

void Conv2d::ForwardSamples(const Matrix& x, int begin, int end, int group, Scratch* scratch) {
  const int oc = out_.channels;
  internal::Epilogue epilogue;
  epilogue.col_bias = bias_.data();
  epilogue.relu = fused_output_relu_;
  const internal::ConstView w{weight_.data(), taps_, oc, 1, taps_};
  for (int b0 = begin; b0 < end; b0 += group) {
    const int count = std::min(group, end - b0);
    const int m = count * pixels_;
    BuildPlanes(x, b0, count, scratch);
    Im2col(GroupPlanes(x, b0, *scratch), count, /*panels=*/true, scratch);
    if (count == 1) {
      // One sample: its pixels x channels product is already the channel-major output.
      internal::GemmPacked(scratch->cols.data(), m, taps_, w, {output_.col(b0).data(), m, oc, 1, m},
                           /*accumulate=*/false, epilogue, &scratch->workspace);
      continue;
    }
    Vector& group_out = scratch->group_out;
    if (group_out.size() < static_cast<int64_t>(m) * oc) {
      group_out.resize(static_cast<int64_t>(m) * oc);
    }
    internal::GemmPacked(scratch->cols.data(), m, taps_, w, {group_out.data(), m, oc, 1, m},
                         /*accumulate=*/false, epilogue, &scratch->workspace);
    // Row (t, pixel), column o of the product is output pixel (o, pixel) of sample b0 + t.
    for (int t = 0; t < count; ++t) {
      float* dst = output_.col(b0 + t).data();
      for (int o = 0; o < oc; ++o) {
        CopyRun(group_out.data() + static_cast<int64_t>(o) * m + static_cast<int64_t>(t) * pixels_,
                pixels_, dst + static_cast<int64_t>(o) * pixels_);
      }
    }
  }
}

const Matrix& Conv2d::Forward(const Matrix& x) {
  RL_CHECK(x.rows() == in_.size()) << Describe() << " got an input with " << x.rows() << " rows";
  input_ = &x;
  const auto batch = static_cast<int>(x.cols());
  output_.resize(out_.size(), batch);
  if (dense_) {
    // One output pixel whose patch is the whole image, taps in input order: y = W^T x + b.
    internal::Epilogue dense;
    dense.row_bias = bias_.data();
    dense.relu = fused_output_relu_;
    const internal::ConstView w{weight_.data(), taps_, out_.channels, 1, taps_};
    internal::Gemm(w.Transposed(), internal::View(x), internal::View(&output_),
                   /*accumulate=*/false, dense, &workspace_);
    return output_;
  }
  const int group = GroupSize(batch);
  const int tasks = PrepareTasks(batch);
  internal::ParallelFor(tasks, [&](int task) {
    ForwardSamples(x, batch * task / tasks, batch * (task + 1) / tasks, group,
                   &scratch_[static_cast<size_t>(task)]);
  });
  return output_;
}

void Conv2d::BackwardSamples(const Matrix& grad_out, int begin, int end, int group, bool input_grad,
                             Matrix* weight_grad, Matrix* bias_grad, Scratch* scratch) {
  const Matrix& x = *input_;
  const int oc = out_.channels;
  for (int b0 = begin; b0 < end; b0 += group) {
    const int count = std::min(group, end - b0);
    const int m = count * pixels_;
    BuildPlanes(x, b0, count, scratch);
    Im2col(GroupPlanes(x, b0, *scratch), count, /*panels=*/false, scratch);

    // The output gradient of the group as an m x out_channels matrix (rows: sample, pixel).
    const float* dy = grad_out.col(b0).data();
    if (count > 1) {
      Vector& group_out = scratch->group_out;
      if (group_out.size() < static_cast<int64_t>(m) * oc) {
        group_out.resize(static_cast<int64_t>(m) * oc);
      }
      for (int t = 0; t < count; ++t) {
        const float* src = grad_out.col(b0 + t).data();
        for (int o = 0; o < oc; ++o) {
          CopyRun(
              src + static_cast<int64_t>(o) * pixels_, pixels_,
              group_out.data() + static_cast<int64_t>(o) * m + static_cast<int64_t>(t) * pixels_);
        }
      }
      dy = group_out.data();
    }
    const internal::ConstView dy_view{dy, m, oc, 1, m};

    // dW += cols^T dY; db += column sums of dY.
    internal::Gemm({scratch->cols.data(), taps_, m, m, 1}, dy_view, internal::View(weight_grad),
                   /*accumulate=*/true, {}, &scratch->workspace);
    *bias_grad += Eigen::Map<const Matrix>(dy, m, oc).colwise().sum().transpose();
    if (!input_grad) continue;

    // dcols = dY W^T, folded back onto the input.
    const int64_t dcols_size = dcols_front_ + static_cast<int64_t>(m) * taps_;
    if (scratch->dcols.size() < dcols_size) scratch->dcols.setZero(dcols_size);
    internal::Gemm(dy_view, {weight_.data(), oc, taps_, taps_, 1},
                   {scratch->dcols.data() + dcols_front_, m, taps_, 1, m}, /*accumulate=*/false, {},
                   &scratch->workspace);
    FoldGradient(x, b0, count, scratch);
  }
}

void Conv2d::BackwardImpl(const Matrix& grad_out, bool input_grad) {
  RL_CHECK(input_ != nullptr) << Describe() << ": Backward() before Forward()";
  const Matrix& x = *input_;
  const auto batch = static_cast<int>(x.cols());
  RL_CHECK(grad_out.rows() == out_.size() && grad_out.cols() == batch)
      << Describe() << " got an output gradient of " << grad_out.rows() << "x" << grad_out.cols()
      << " for a batch of " << batch;
  if (input_grad) grad_input_.resize(in_.size(), batch);
  if (dense_) {
    // As a fully connected layer with weight W^T: dW += x dY^T, db += row sums of dY,
    // dx = W dY.
    internal::Gemm(internal::View(x), internal::View(grad_out).Transposed(),
                   internal::View(&weight_grad_), /*accumulate=*/true, {}, &workspace_);
    internal::AddRowSums(grad_out, bias_grad_.data());
    if (!input_grad) return;
    internal::Epilogue mask;
    if (fused_input_relu_grad_) mask.mask = x.data();
    internal::Gemm(internal::View(weight_), internal::View(grad_out), internal::View(&grad_input_),
                   /*accumulate=*/false, mask, &workspace_);
    return;
  }
  const int group = GroupSize(batch);
  const int tasks = PrepareTasks(batch);
  internal::ParallelFor(tasks, [&](int task) {
    Scratch& scratch = scratch_[static_cast<size_t>(task)];
    Matrix* weight_grad = &weight_grad_;
    Matrix* bias_grad = &bias_grad_;
    if (task > 0) {
      scratch.weight_grad.setZero(weight_grad_.rows(), weight_grad_.cols());
      scratch.bias_grad.setZero(bias_grad_.rows(), 1);
      weight_grad = &scratch.weight_grad;
      bias_grad = &scratch.bias_grad;
    }
    BackwardSamples(grad_out, batch * task / tasks, batch * (task + 1) / tasks, group, input_grad,
                    weight_grad, bias_grad, &scratch);
  });
  for (int task = 1; task < tasks; ++task) {
    weight_grad_ += scratch_[static_cast<size_t>(task)].weight_grad;
    bias_grad_ += scratch_[static_cast<size_t>(task)].bias_grad;
  }
}

const Matrix& Conv2d::Backward(const Matrix& grad_out) {
  BackwardImpl(grad_out, /*input_grad=*/true);
  return grad_input_;
}

void Conv2d::BackwardParams(const Matrix& grad_out) {
  BackwardImpl(grad_out, /*input_grad=*/false);
}

std::vector<Param> Conv2d::Params() {
  return {{"weight", &weight_, &weight_grad_}, {"bias", &bias_, &bias_grad_}};
}

std::string Conv2d::Describe() const {
  return ConvName(in_.channels, out_.channels, kernel_, stride_, padding_, in_.height, in_.width);
}

std::unique_ptr<Layer> Conv2d::Clone() const {
  auto copy = std::make_unique<Conv2d>(*this);
  copy->weight_grad_.setZero();
  copy->bias_grad_.setZero();
  copy->input_ = nullptr;
  copy->fused_output_relu_ = false;
  copy->fused_input_relu_grad_ = false;
  return copy;
}

}  // namespace rl::nn
