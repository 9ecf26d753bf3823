// Max and average pooling over k x k windows with stride k and no padding (floor mode), as
// PyTorch's nn.MaxPool2d(k) and nn.AvgPool2d(k): the pooling layers of the TD3 CarRacing
// article's encoder (conv 4x4/2, max-pool 2, conv 4x4/2, average-pool 2).
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "nn/layer.h"
#include "nn/tensor.h"

namespace rl::nn {

/// channels x height x width images (one per column, channel-major; see ImageShape) to channels x
/// (height / k) x (width / k). Max: each output is the largest of its window, and its gradient
/// goes to that input (the first on ties). Average: the window's mean, the gradient shared
/// equally. Architecture strings "maxpool2d(channels,k,height,width)" and
/// "avgpool2d(channels,k,height,width)". No allocation once the batch size is stable.
class Pool2d : public Layer {
 public:
  enum class Mode { kMax, kAverage };
  /// Throws std::invalid_argument unless every size is positive and k <= height, width.
  Pool2d(Mode mode, int channels, int kernel, int height, int width);

  const Matrix& Forward(const Matrix& x) override;
  const Matrix& Backward(const Matrix& grad_out) override;
  std::string Describe() const override;
  std::unique_ptr<Layer> Clone() const override;
  int input_size() const override { return in_.size(); }
  int output_size() const override { return out_.size(); }
  ImageShape input_shape() const override { return in_; }
  ImageShape output_shape() const override { return out_; }

 private:
  // Forward and Backward of samples [begin, end): a share of the batch for one thread.
  void ForwardSamples(const Matrix& x, int begin, int end);
  void BackwardSamples(const Matrix& grad_out, int begin, int end);

  Mode mode_;
  int kernel_;
  ImageShape in_, out_;
  Matrix output_, grad_input_;
  std::vector<int> argmax_;  // max mode: input row of each output element, column by column
  int batch_ = 0;
};

}  // namespace rl::nn
