#include "nn/conv2d.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <string>

#include "common/check.h"
#include "nn/gemm.h"
#include "nn/init.h"
#include "nn/kernels.h"
#include "nn/parallel.h"

namespace rl::nn {
namespace {

// Floats of unfolded input per group: the group is as many samples as fit, so that the unfolded
// matrix (about 512 KB) stays in the L2 cache while the kernel reads it.
constexpr int64_t kColsBudget = 128 * 1024;

// How far ahead of the input row being split BuildPlanes() asks for input (floats, 4 KB): a
// batch's input is mostly read from memory, and the hardware prefetcher starts late on each
// sample's rows. Measured on AMD Zen 5: twice the speed of the split of uncached 84-float rows.
constexpr int64_t kPrefetchFloats = 1024;

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
  geo_.in_channels = in_channels;
  geo_.kernel = kernel;
  geo_.stride = stride;
  geo_.out_h = out_.height;
  geo_.out_w = out_.width;
  geo_.taps = in_channels * kernel * kernel;
  geo_.pixels = out_.height * out_.width;
  direct_ = stride == 1 && padding == 0;
  dense_ = padding == 0 && kernel == in_h && kernel == in_w;
  if (direct_) {
    geo_.plane_h = in_h;
    geo_.plane_w = in_w;
    geo_.plane_stride = in_.size();
  } else {
    geo_.plane_h = (in_h + 2 * padding + stride - 1) / stride;
    geo_.plane_w = (in_w + 2 * padding + stride - 1) / stride;
    geo_.plane_stride =
        static_cast<int64_t>(in_channels) * stride * stride * geo_.plane_h * geo_.plane_w;
  }

  geo_.window_span = (out_.height - 1) * geo_.plane_w + out_.width;
  if (geo_.window_span <= 16) {
    for (int i = 0; i < 16; ++i) {
      geo_.window_index[i] = i < geo_.pixels ? (i / out_.width) * geo_.plane_w + i % out_.width : 0;
    }
  }
  geo_.tap_offset.resize(geo_.taps);
  for (int c = 0; c < in_channels; ++c) {
    for (int ky = 0; ky < kernel; ++ky) {
      for (int kx = 0; kx < kernel; ++kx) {
        const int64_t plane =
            (static_cast<int64_t>(c) * stride + ky % stride) * stride + kx % stride;
        geo_.tap_offset[(c * kernel + ky) * kernel + kx] =
            plane * geo_.plane_h * geo_.plane_w + static_cast<int64_t>(ky / stride) * geo_.plane_w +
            kx / stride;
      }
    }
  }
  dcols_front_ = (kernel + 15) / 16 * 16;
  scratch_.resize(1);

  weight_.resize(geo_.taps, out_channels);
  bias_.resize(out_channels, 1);
  const float bound = 1.0f / std::sqrt(static_cast<float>(geo_.taps));
  FillUniform(bound, rng, &weight_);
  FillUniform(bound, rng, &bias_);
  weight_grad_.setZero(geo_.taps, out_channels);
  bias_grad_.setZero(out_channels, 1);
}

int Conv2d::GroupSize(int batch, bool pairs) const {
  // bf16 pairs take half the space of floats.
  const int64_t per_sample =
      static_cast<int64_t>(geo_.pixels) * (pairs ? (geo_.taps + 1) / 2 : geo_.taps);
  return static_cast<int>(std::clamp<int64_t>(kColsBudget / per_sample, 1, std::max(batch, 1)));
}

void Conv2d::BuildPlanes(const Matrix& x, int b0, int count, Scratch* scratch) const {
  if (direct_) return;
  const int s = stride_;
  const int p = padding_;
  const int h = in_.height;
  const int w = in_.width;
  const int row_len = geo_.plane_w * s;  // A padded input row, extended to whole plane columns.
  const int64_t plane_size = static_cast<int64_t>(geo_.plane_h) * geo_.plane_w;
  if (scratch->planes.size() < geo_.plane_stride * count)
    scratch->planes.resize(geo_.plane_stride * count);
  if (scratch->padded_row.size() < row_len) scratch->padded_row.resize(row_len);
  const internal::KernelSet& kernels = internal::Kernels();
  // Plane (c, py, px) holds the pixels (Y * s + py, X * s + px) of the zero-padded channel c:
  // padded row Y * s + py is split into the s planes (c, py, .) at row Y. Without padding on the
  // left, input rows are split in place (the split reads zeros past their end); otherwise through
  // a zero-padded copy.
  for (int t = 0; t < count; ++t) {
    const float* image = x.col(b0 + t).data();
    float* sample_planes = scratch->planes.data() + t * geo_.plane_stride;
    for (int c = 0; c < in_.channels; ++c) {
      const float* channel = image + static_cast<int64_t>(c) * h * w;
      for (int yp = 0; yp < geo_.plane_h * s; ++yp) {
        float* dst = sample_planes + (static_cast<int64_t>(c) * s + yp % s) * s * plane_size +
                     static_cast<int64_t>(yp / s) * geo_.plane_w;
        const int iy = yp - p;
        if (iy < 0 || iy >= h) {
          for (int px = 0; px < s; ++px) {
            std::fill(dst + px * plane_size, dst + px * plane_size + geo_.plane_w, 0.0f);
          }
          continue;
        }
        const float* row = channel + static_cast<int64_t>(iy) * w;
        const int64_t ahead = (row - x.data()) + kPrefetchFloats;
        if (ahead + w <= x.size()) {
          for (int i = 0; i < w; i += 16) __builtin_prefetch(x.data() + ahead + i);
        }
        if (p == 0) {
          kernels.deinterleave(row, w, s, geo_.plane_w, plane_size, dst);
          continue;
        }
        // The padding is rewritten every time: Backward() reuses this row.
        float* padded = scratch->padded_row.data();
        std::fill(padded, padded + p, 0.0f);
        std::copy(row, row + w, padded + p);
        std::fill(padded + p + w, padded + row_len, 0.0f);
        kernels.deinterleave(padded, row_len, s, geo_.plane_w, plane_size, dst);
      }
    }
  }
}

const float* Conv2d::GroupPlanes(const Matrix& x, int b0, const Scratch& scratch) const {
  return direct_ ? x.col(b0).data() : scratch.planes.data();
}

bool Conv2d::UnfoldsToPairs() const {
  return precision_ == Precision::kBf16 && internal::Kernels().im2col_pairs != nullptr;
}

void Conv2d::Im2col(const float* planes, int count, bool panels, Scratch* scratch) const {
  const int64_t m = static_cast<int64_t>(count) * geo_.pixels;
  const internal::KernelSet& kernels = internal::Kernels();
  if (panels && UnfoldsToPairs()) {
    // Pairs are 4 bytes, as floats.
    const int64_t size = internal::PackedPairs(static_cast<int>(m), geo_.taps);
    if (scratch->cols.size() < size) scratch->cols.setZero(size);
    kernels.im2col_pairs(geo_, planes, count, reinterpret_cast<uint32_t*>(scratch->cols.data()));
    return;
  }
  if (panels) {
    const int rows = internal::PackedPanelRows(precision_);
    const int64_t size = (m + rows - 1) / rows * rows * geo_.taps;
    if (scratch->cols.size() < size) scratch->cols.setZero(size);
    kernels.im2col_panels(geo_, planes, count, rows, scratch->cols.data());
    return;
  }
  if (scratch->cols.size() < m * geo_.taps) scratch->cols.resize(m * geo_.taps);
  kernels.im2col(geo_, planes, count, scratch->cols.data());
}

void Conv2d::PlaneGradient(const float* dcols, int count, int t, int c, int py, int px, float* out,
                           Scratch* scratch) const {
  const int s = stride_;
  const int k = kernel_;
  const int64_t m = static_cast<int64_t>(count) * geo_.pixels;
  // Pixel (Y, X) of phase plane (c, py, px) was copied by Im2col() into column (c, ky, kx),
  // ky = KY * s + py, kx = KX * s + px, at output pixel (Y - KY, X - KX). Each (KY, KX) adds a
  // block of oh x ow entries of that column, shifted by (KY, KX), to the plane.
  int n_runs = 0;
  for (int ky = py, ky_step = 0; ky < k; ky += s, ++ky_step) {
    for (int kx = px, kx_step = 0; kx < k; kx += s, ++kx_step) {
      const int64_t tap = (static_cast<int64_t>(c) * k + ky) * k + kx;
      scratch->runs[static_cast<size_t>(n_runs)] = {
          dcols + tap * m + static_cast<int64_t>(t) * geo_.pixels, ky_step, kx_step};
      ++n_runs;
    }
  }
  internal::Kernels().plane_gradient(geo_, scratch->runs.data(), n_runs, out);
}

void Conv2d::FoldGradient(const Matrix& x, int b0, int count, Scratch* scratch) {
  const int s = stride_;
  const int p = padding_;
  const int h = in_.height;
  const int w = in_.width;
  const int64_t plane_size = static_cast<int64_t>(geo_.plane_h) * geo_.plane_w;
  const float* dcols = scratch->dcols.data() + dcols_front_;
  const auto steps = static_cast<size_t>((kernel_ + s - 1) / s);
  if (scratch->runs.size() < steps * steps) scratch->runs.resize(steps * steps);
  if (!direct_ && scratch->channel_grad.size() < s * s * plane_size) {
    scratch->channel_grad.resize(s * s * plane_size);
  }
  const internal::KernelSet& kernels = internal::Kernels();
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
              planes + static_cast<int64_t>(yp % s) * s * plane_size + (yp / s) * geo_.plane_w;
          float* dst = dx_image + at + static_cast<int64_t>(iy) * w;
          if (p == 0 && geo_.plane_w * s == w) {
            kernels.interleave(rows, s, geo_.plane_w, plane_size, dst);
            continue;
          }
          for (int px = 0; px < s; ++px) {
            // Plane column X holds input column X * s + px - p.
            const float* src = rows + px * plane_size;
            const int x_lo = std::max(0, (p - px + s - 1) / s);
            const int x_hi = std::min(geo_.plane_w, (w + p - px + s - 1) / s);
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
  const int64_t work = static_cast<int64_t>(batch) * geo_.pixels * geo_.taps * out_.channels;
  const int tasks = internal::TasksFor(work, batch);
  if (static_cast<int>(scratch_.size()) < tasks) scratch_.resize(static_cast<size_t>(tasks));
  return tasks;
}

void Conv2d::ForwardSamples(const Matrix& x, int begin, int end, int group, Scratch* scratch) {
  const int oc = out_.channels;
  internal::Epilogue epilogue;
  epilogue.col_bias = bias_.data();
  epilogue.relu = fused_output_relu_;
  const internal::ConstView w{weight_.data(), geo_.taps, oc, 1, geo_.taps};
  const internal::KernelSet& kernels = internal::Kernels();
  const bool pairs = UnfoldsToPairs();
  // The unfolded group (packed panels, or bf16 pairs) times the weight, into `out`.
  auto product = [&](int m, float* out) {
    const internal::MutView c{out, m, oc, 1, m};
    if (pairs) {
      internal::GemmPackedPairs(reinterpret_cast<const uint32_t*>(scratch->cols.data()), m,
                                geo_.taps, w, c, /*accumulate=*/false, epilogue,
                                &scratch->workspace);
    } else {
      internal::GemmPacked(scratch->cols.data(), m, geo_.taps, w, c, /*accumulate=*/false, epilogue,
                           &scratch->workspace, precision_);
    }
  };
  for (int b0 = begin; b0 < end; b0 += group) {
    const int count = std::min(group, end - b0);
    const int m = count * geo_.pixels;
    BuildPlanes(x, b0, count, scratch);
    Im2col(GroupPlanes(x, b0, *scratch), count, /*panels=*/true, scratch);
    if (count == 1) {
      // One sample: its pixels x channels product is already the channel-major output.
      product(m, output_.col(b0).data());
      continue;
    }
    Vector& group_out = scratch->group_out;
    if (group_out.size() < static_cast<int64_t>(m) * oc) {
      group_out.resize(static_cast<int64_t>(m) * oc);
    }
    product(m, group_out.data());
    // Row (t, pixel), column o of the product is output pixel (o, pixel) of sample b0 + t.
    for (int t = 0; t < count; ++t) {
      kernels.copy_runs(group_out.data() + static_cast<int64_t>(t) * geo_.pixels, m,
                        output_.col(b0 + t).data(), geo_.pixels, oc, geo_.pixels);
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
    const internal::ConstView w{weight_.data(), geo_.taps, out_.channels, 1, geo_.taps};
    internal::Gemm(w.Transposed(), internal::View(x), internal::View(&output_),
                   /*accumulate=*/false, dense, &workspace_, precision_);
    return output_;
  }
  const int group = GroupSize(batch, UnfoldsToPairs());
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
  const internal::KernelSet& kernels = internal::Kernels();
  for (int b0 = begin; b0 < end; b0 += group) {
    const int count = std::min(group, end - b0);
    const int m = count * geo_.pixels;
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
        kernels.copy_runs(grad_out.col(b0 + t).data(), geo_.pixels,
                          group_out.data() + static_cast<int64_t>(t) * geo_.pixels, m, oc,
                          geo_.pixels);
      }
      dy = group_out.data();
    }
    const internal::ConstView dy_view{dy, m, oc, 1, m};

    // dW += cols^T dY; db += column sums of dY.
    internal::Gemm({scratch->cols.data(), geo_.taps, m, m, 1}, dy_view, internal::View(weight_grad),
                   /*accumulate=*/true, {}, &scratch->workspace, precision_);
    *bias_grad += Eigen::Map<const Matrix>(dy, m, oc).colwise().sum().transpose();
    if (!input_grad) continue;

    // dcols = dY W^T, folded back onto the input.
    const int64_t dcols_size = dcols_front_ + static_cast<int64_t>(m) * geo_.taps;
    if (scratch->dcols.size() < dcols_size) scratch->dcols.setZero(dcols_size);
    internal::Gemm(dy_view, {weight_.data(), oc, geo_.taps, geo_.taps, 1},
                   {scratch->dcols.data() + dcols_front_, m, geo_.taps, 1, m},
                   /*accumulate=*/false, {}, &scratch->workspace, precision_);
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
                   internal::View(&weight_grad_), /*accumulate=*/true, {}, &workspace_, precision_);
    internal::AddRowSums(grad_out, bias_grad_.data());
    if (!input_grad) return;
    internal::Epilogue mask;
    if (fused_input_relu_grad_) mask.mask = x.data();
    internal::Gemm(internal::View(weight_), internal::View(grad_out), internal::View(&grad_input_),
                   /*accumulate=*/false, mask, &workspace_, precision_);
    return;
  }
  const int group = GroupSize(batch, /*pairs=*/false);
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
