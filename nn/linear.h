// Fully connected layer y = W x + b.
#pragma once

#include <cstdint>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "nn/gemm.h"
#include "nn/layer.h"
#include "nn/tensor.h"

namespace rl::nn {

/// y = W x + b for a batch x of `in` x batch; W is out x in, b is out x 1.
///
/// Forward() keeps a pointer to x for Backward() (see Layer). Batched products go through a
/// register-blocked kernel, single columns through Eigen's matrix-vector product; neither
/// allocates once the batch size is stable. In bf16 on the CPU's instructions the forward product
/// reads W rounded into bf16 pairs once per change of W (Param::version: the optimizers' steps,
/// Sequential's copies, weight()), not once per Forward(): a target network's weight is rounded
/// once per copy, an online one once per step however many forward passes the step makes.
class Linear : public Layer {
 public:
  /// Initialises W and b like PyTorch's nn.Linear: every entry ~ U(-1/sqrt(in), 1/sqrt(in)),
  /// W first (in storage order), then b. `in` and `out` must be positive.
  Linear(int in, int out, std::mt19937* rng);
  /// A layer with the given parameters; `bias` must be weight.rows() x 1.
  Linear(Matrix weight, Matrix bias);

  const Matrix& Forward(const Matrix& x) override;
  const Matrix& Backward(const Matrix& grad_out) override;
  void BackwardParams(const Matrix& grad_out) override;
  std::vector<Param> Params() override;
  std::string Describe() const override;
  std::unique_ptr<Layer> Clone() const override;
  int input_size() const override { return static_cast<int>(weight_.cols()); }
  int output_size() const override { return static_cast<int>(weight_.rows()); }

  /// Marks the weight changed: write through the reference before the next Forward(), not after.
  Matrix& weight() {
    ++weight_version_;
    return weight_;
  }
  const Matrix& weight() const { return weight_; }
  Matrix& bias() { return bias_; }
  const Matrix& bias() const { return bias_; }
  const Matrix& weight_grad() const { return weight_grad_; }
  const Matrix& bias_grad() const { return bias_grad_; }

  /// Fuses a ReLU that follows this layer into its forward pass: Forward() then returns
  /// max(W x + b, 0). Set by Sequential, which then skips the ReLU's own pass.
  void set_fused_output_relu(bool on) { fused_output_relu_ = on; }
  /// Fuses the backward pass of a ReLU that precedes this layer: Backward() then returns the
  /// gradient with respect to the ReLU's input, zero wherever this layer's input (the ReLU's
  /// output) is 0. Set by Sequential, which then skips the ReLU's Backward().
  void set_fused_input_relu_grad(bool on) { fused_input_relu_grad_ = on; }
  void set_precision(Precision precision) override { precision_ = precision; }
  bool FuseOutputRelu() override {
    set_fused_output_relu(true);
    return true;
  }
  bool FuseInputReluGrad() override {
    set_fused_input_relu_grad(true);
    return true;
  }

 private:
  // Adds dW and db for `grad_out` and the input of the last Forward().
  void AccumulateParamGrads(const Matrix& grad_out);
  // Whether this forward pass reads W from weight_pairs_ (rounding them again if W changed):
  // when W is as it was at the last pass, or changed while its last pairs served several passes.
  // A weight that changes between every two passes (an online network evaluated once per step)
  // is rounded as the product packs it, which costs less than rounding all of it and reading it
  // back (the result is the same bit for bit).
  bool UseWeightPairs();

  Matrix weight_;                       // out x in
  Matrix bias_;                         // out x 1
  Matrix weight_grad_;                  // out x in
  Matrix bias_grad_;                    // out x 1
  Matrix output_;                       // out x batch
  Matrix grad_input_;                   // in x batch
  const Matrix* input_ = nullptr;       // The x of the last Forward().
  internal::GemmWorkspace workspace_;   // Scratch space of the products.
  std::vector<uint32_t> weight_pairs_;  // W as it was at pairs_version_, in bf16 pairs (or none).
  uint64_t weight_version_ = 0;         // Param::version of W.
  uint64_t pairs_version_ = 0;
  uint64_t seen_version_ = 0;  // The version of W at the last bf16 forward pass.
  int passes_at_version_ = 0;  // bf16 forward passes at seen_version_.
  bool pairs_pay_ = true;      // The last version of W served several passes.
  bool fused_output_relu_ = false;
  bool fused_input_relu_grad_ = false;
  Precision precision_ = Precision::kFp32;
};

}  // namespace rl::nn
