// 2-D convolution over images stored one per column (see ImageShape in nn/tensor.h).
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "nn/gemm.h"
#include "nn/kernels.h"
#include "nn/layer.h"
#include "nn/precision.h"
#include "nn/tensor.h"

namespace rl::nn {

/// A 2-D convolution with PyTorch's nn.Conv2d semantics (cross-correlation, square kernel, equal
/// stride and zero padding on both axes, bias). Input: in_channels x in_h x in_w images, output:
/// out_channels x out_h x out_w with out_h = (in_h + 2 padding - kernel) / stride + 1 (floor), both
/// channel-major in the columns of a batch.
///
/// The weight is a (in_channels * kernel * kernel) x out_channels matrix: column o is filter o
/// with its taps in (channel, row, column) order, so its storage order is that of PyTorch's
/// (out, in, kh, kw) weight tensor. The bias has out_channels rows.
///
/// Each group of samples (as many as fit about 512 KB) is unfolded into a matrix with one row per
/// output pixel and one column per filter tap (im2col, through a stride x stride phase
/// decomposition of the padded input, so every copy is a contiguous run), which is multiplied by
/// the weight with the register-blocked kernel of gemm.h; the bias and a fused ReLU are applied as
/// results are stored. Backward() unfolds the input again rather than keeping the unfolded batch
/// (so Forward() keeps a pointer to its input, see Layer), computes dW = cols^T dY and
/// dcols = dY W^T with the same kernel, and folds dcols back by gathering, for every input pixel,
/// the entries copied from it. A kernel that covers the whole unpadded input is computed as a
/// fully connected layer. Nothing allocates once the batch size (and the thread count) is stable.
///
/// With more than one thread (SetNumThreads(), nn/parallel.h) the batch is cut into contiguous
/// shares, one per thread, each with its own scratch space. Outputs and input gradients are the
/// single-threaded ones bit for bit; each share sums its own parameter gradients, which are then
/// added in share order, so those differ from the single-threaded ones by rounding only.
///
/// On one AVX-512 core at batch 32 the three layers of the Nature network run at about 70-85
/// GFLOP/s forward and 65-80 backward, against about 100 for the bare product kernel.
class Conv2d : public Layer {
 public:
  /// Initialises like PyTorch (kaiming_uniform with a = sqrt(5)): weight and bias entries ~
  /// U(-1/sqrt(fan_in), 1/sqrt(fan_in)), fan_in = in_channels * kernel * kernel, the weight first
  /// (in storage order). Throws std::invalid_argument unless all sizes are positive, padding >= 0
  /// and the kernel fits the padded input.
  Conv2d(int in_channels, int out_channels, int kernel, int stride, int padding, int in_h, int in_w,
         std::mt19937* rng);

  const Matrix& Forward(const Matrix& x) override;
  const Matrix& Backward(const Matrix& grad_out) override;
  void BackwardParams(const Matrix& grad_out) override;
  std::vector<Param> Params() override;
  std::string Describe() const override;
  std::unique_ptr<Layer> Clone() const override;
  int input_size() const override { return in_.size(); }
  int output_size() const override { return out_.size(); }
  ImageShape input_shape() const override { return in_; }
  ImageShape output_shape() const override { return out_; }
  void set_precision(Precision precision) override { precision_ = precision; }
  bool FuseOutputRelu() override {
    fused_output_relu_ = true;
    return true;
  }
  bool FuseInputReluGrad() override {
    fused_input_relu_grad_ = true;
    return true;
  }

  int kernel() const { return kernel_; }
  int stride() const { return stride_; }
  int padding() const { return padding_; }
  Matrix& weight() { return weight_; }
  const Matrix& weight() const { return weight_; }
  Matrix& bias() { return bias_; }
  const Matrix& bias() const { return bias_; }
  const Matrix& weight_grad() const { return weight_grad_; }
  const Matrix& bias_grad() const { return bias_grad_; }

 private:
  // Scratch space of one task of Forward()/Backward() (task t of a call with T tasks works on
  // samples [batch t / T, batch (t + 1) / T)), grown to the largest group it has seen.
  struct Scratch {
    Vector planes;      // Phase planes of one group.
    Vector padded_row;  // A zero-padded input row: plane_w_ * stride floats.
    Vector cols;        // Unfolded group: (group * P) x taps, column-major or packed.
    Vector group_out;   // (group * P) x out_channels: a product before it is scattered.
    Vector dcols;       // Gradient of cols, after dcols_front_ floats of slack.
    std::vector<internal::GradientRun> runs;  // (kernel / stride, rounded up)^2 entries.
    Vector channel_grad;                // The gradient of the stride^2 phase planes of one channel.
    internal::GemmWorkspace workspace;  // Scratch space of the products.
    // Tasks after the first: the parameter gradients of their samples, added to weight_grad_ and
    // bias_grad_ (in task order) once all tasks are done. The first task adds into those directly.
    Matrix weight_grad;
    Matrix bias_grad;
  };

  // Copies the phase planes of samples [b0, b0 + count) of x into s->planes, unless the input is
  // read in place (stride 1, no padding).
  void BuildPlanes(const Matrix& x, int b0, int count, Scratch* s) const;
  // Pointer to the planes of the group's first sample; samples are geo_.plane_stride floats apart.
  const float* GroupPlanes(const Matrix& x, int b0, const Scratch& s) const;
  // Unfolds `count` samples whose planes start at `planes` into s->cols ((count * P) x K):
  // column-major, or, when `panels`, packed in panels for internal::GemmPacked() (in bf16 on a
  // path with the instructions: in the bf16 pairs of internal::GemmPackedPairs()).
  void Im2col(const float* planes, int count, bool panels, Scratch* s) const;
  // Writes d(loss)/d(x) of samples [b0, b0 + count) from their unfolded gradient s->dcols (the
  // transpose of Im2col(), as a gather: every input pixel sums the entries copied from it).
  void FoldGradient(const Matrix& x, int b0, int count, Scratch* s);
  // Writes the gradient of phase plane (c, py, px) of sample t of the group into `out`
  // (plane_h_ x plane_w_, row-major).
  void PlaneGradient(const float* dcols, int count, int t, int c, int py, int px, float* out,
                     Scratch* s) const;
  // Samples per group for a batch of `batch`, unfolded into floats or bf16 `pairs`.
  int GroupSize(int batch, bool pairs) const;
  // Whether Forward() unfolds straight into bf16 pairs (bf16 on a path with the instructions).
  bool UnfoldsToPairs() const;
  // How many tasks to split a batch of `batch` into, with scratch_ grown to that many.
  int PrepareTasks(int batch);
  // Forward() of samples [begin, end) of x, in groups of `group`.
  void ForwardSamples(const Matrix& x, int begin, int end, int group, Scratch* s);
  // Backward of samples [begin, end): adds their parameter gradients into weight_grad and
  // bias_grad and, when input_grad, writes their columns of grad_input_.
  void BackwardSamples(const Matrix& grad_out, int begin, int end, int group, bool input_grad,
                       Matrix* weight_grad, Matrix* bias_grad, Scratch* s);
  // Shared part of Backward() and BackwardParams().
  void BackwardImpl(const Matrix& grad_out, bool input_grad);

  ImageShape in_;
  ImageShape out_;
  int kernel_;
  int stride_;
  int padding_;
  bool direct_;  // Stride 1 and no padding: the input is its own (only) phase plane.
  bool dense_;   // The kernel covers the unpadded input: a fully connected layer on the image.
  // The shape as the kernels see it: taps (in_channels * kernel * kernel, the rows of the
  // weight), pixels, the phase planes (one plane, the input itself, if direct_).
  internal::ConvGeometry geo_;
  int dcols_front_;  // Floats of slack in front of the unfolded gradient (Scratch::dcols).
  Precision precision_ = Precision::kFp32;

  Matrix weight_;  // taps x out_channels.
  Matrix bias_;    // out_channels x 1.
  Matrix weight_grad_;
  Matrix bias_grad_;
  Matrix output_;                      // out_.size() x batch.
  Matrix grad_input_;                  // in_.size() x batch.
  const Matrix* input_ = nullptr;      // The x of the last Forward().
  std::vector<Scratch> scratch_;       // One per task; one until threads are used.
  internal::GemmWorkspace workspace_;  // Scratch space of the products in the dense case.
  bool fused_output_relu_ = false;
  bool fused_input_relu_grad_ = false;
};

}  // namespace rl::nn
