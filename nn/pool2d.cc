#include "nn/pool2d.h"

#include <algorithm>
#include <stdexcept>

#include "common/check.h"
#include "nn/parallel.h"

namespace rl::nn {
namespace {

// One output row of a 2 x 2 max pooling: rows r0 and r1 of the input, whose first pixel has index
// `first`. The candidates are compared in the order of the general loop (row 0 then 1, column 0
// then 1) and the first of equal maxima is kept, without branches, so that the compiler
// vectorises the loop (the general loop compares one pixel at a time).
void MaxPoolRow2(const float* __restrict r0, const float* __restrict r1, int width, int out_w,
                 int first, float* __restrict out, int* __restrict arg) {
  for (int ox = 0; ox < out_w; ++ox) {
    float best = r0[2 * ox];
    int at = 2 * ox;
    const float b = r0[2 * ox + 1];
    at = b > best ? 2 * ox + 1 : at;
    best = b > best ? b : best;
    const float c = r1[2 * ox];
    at = c > best ? width + 2 * ox : at;
    best = c > best ? c : best;
    const float d = r1[2 * ox + 1];
    at = d > best ? width + 2 * ox + 1 : at;
    best = d > best ? d : best;
    out[ox] = best;
    arg[ox] = first + at;
  }
}

}  // namespace

Pool2d::Pool2d(Mode mode, int channels, int kernel, int height, int width)
    : mode_(mode), kernel_(kernel) {
  if (channels < 1 || kernel < 1 || height < kernel || width < kernel) {
    throw std::invalid_argument(
        "pool2d: needs positive channels and kernel, and a kernel within the " +
        std::to_string(height) + "x" + std::to_string(width) + " image");
  }
  in_ = ImageShape{.channels = channels, .height = height, .width = width};
  out_ = ImageShape{.channels = channels, .height = height / kernel, .width = width / kernel};
}

std::string Pool2d::Describe() const {
  return std::string(mode_ == Mode::kMax ? "maxpool2d(" : "avgpool2d(") +
         std::to_string(in_.channels) + "," + std::to_string(kernel_) + "," +
         std::to_string(in_.height) + "," + std::to_string(in_.width) + ")";
}

std::unique_ptr<Layer> Pool2d::Clone() const {
  return std::make_unique<Pool2d>(mode_, in_.channels, kernel_, in_.height, in_.width);
}

const Matrix& Pool2d::Forward(const Matrix& x) {
  RL_CHECK(x.rows() == in_.size()) << Describe() << ": input has " << x.rows() << " rows";
  batch_ = static_cast<int>(x.cols());
  output_.resize(out_.size(), batch_);
  if (mode_ == Mode::kMax) argmax_.resize(static_cast<size_t>(out_.size()) * batch_);
  internal::ParallelForColumns(batch_, int64_t{in_.size()} * batch_,
                               [&](int64_t begin, int64_t end) {
                                 ForwardSamples(x, static_cast<int>(begin), static_cast<int>(end));
                               });
  return output_;
}

void Pool2d::ForwardSamples(const Matrix& x, int begin, int end) {
  const float scale = 1.0f / static_cast<float>(kernel_ * kernel_);
  for (int n = begin; n < end; ++n) {
    const float* in = x.col(n).data();
    float* out = output_.col(n).data();
    int* arg = mode_ == Mode::kMax ? &argmax_[static_cast<size_t>(n) * out_.size()] : nullptr;
    for (int c = 0; c < in_.channels; ++c) {
      const int plane = c * in_.height * in_.width;
      for (int oy = 0; oy < out_.height; ++oy) {
        if (mode_ == Mode::kMax && kernel_ == 2) {
          const int o = (c * out_.height + oy) * out_.width;
          const int first = plane + 2 * oy * in_.width;
          MaxPoolRow2(in + first, in + first + in_.width, in_.width, out_.width, first, out + o,
                      arg + o);
          continue;
        }
        for (int ox = 0; ox < out_.width; ++ox) {
          const int o = (c * out_.height + oy) * out_.width + ox;
          const int first = plane + oy * kernel_ * in_.width + ox * kernel_;
          if (mode_ == Mode::kMax) {
            int best = first;
            for (int ky = 0; ky < kernel_; ++ky) {
              for (int kx = 0; kx < kernel_; ++kx) {
                const int i = first + ky * in_.width + kx;
                if (in[i] > in[best]) best = i;
              }
            }
            out[o] = in[best];
            arg[o] = best;
          } else {
            float sum = 0;
            for (int ky = 0; ky < kernel_; ++ky) {
              for (int kx = 0; kx < kernel_; ++kx) sum += in[first + ky * in_.width + kx];
            }
            out[o] = sum * scale;
          }
        }
      }
    }
  }
}

const Matrix& Pool2d::Backward(const Matrix& grad_out) {
  RL_CHECK(grad_out.rows() == out_.size() && grad_out.cols() == batch_)
      << Describe() << ": output gradient is " << grad_out.rows() << "x" << grad_out.cols();
  grad_input_.resize(in_.size(), batch_);
  internal::ParallelForColumns(
      batch_, int64_t{in_.size()} * batch_, [&](int64_t begin, int64_t end) {
        BackwardSamples(grad_out, static_cast<int>(begin), static_cast<int>(end));
      });
  return grad_input_;
}

void Pool2d::BackwardSamples(const Matrix& grad_out, int begin, int end) {
  const float scale = 1.0f / static_cast<float>(kernel_ * kernel_);
  for (int n = begin; n < end; ++n) {
    const float* g = grad_out.col(n).data();
    float* gi = grad_input_.col(n).data();
    std::fill(gi, gi + in_.size(), 0.0f);
    if (mode_ == Mode::kMax) {
      const int* arg = &argmax_[static_cast<size_t>(n) * out_.size()];
      for (int o = 0; o < out_.size(); ++o) gi[arg[o]] += g[o];
      continue;
    }
    for (int c = 0; c < in_.channels; ++c) {
      const int plane = c * in_.height * in_.width;
      for (int oy = 0; oy < out_.height; ++oy) {
        for (int ox = 0; ox < out_.width; ++ox) {
          const float share = g[(c * out_.height + oy) * out_.width + ox] * scale;
          const int first = plane + oy * kernel_ * in_.width + ox * kernel_;
          for (int ky = 0; ky < kernel_; ++ky) {
            for (int kx = 0; kx < kernel_; ++kx) gi[first + ky * in_.width + kx] += share;
          }
        }
      }
    }
  }
}

}  // namespace rl::nn
