#include "nn/linear.h"

#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>

#include "common/check.h"
#include "nn/gemm.h"
#include "nn/gemv.h"
#include "nn/init.h"

namespace rl::nn {

Linear::Linear(int in, int out, std::mt19937* rng) {
  if (in <= 0 || out <= 0) {
    throw std::invalid_argument("linear(" + std::to_string(in) + "," + std::to_string(out) +
                                "): sizes must be positive");
  }
  RL_CHECK(rng != nullptr) << "Linear needs a random generator";
  weight_.resize(out, in);
  bias_.resize(out, 1);
  const float bound = 1.0f / std::sqrt(static_cast<float>(in));
  FillUniform(bound, rng, &weight_);
  FillUniform(bound, rng, &bias_);
  weight_grad_.setZero(out, in);
  bias_grad_.setZero(out, 1);
}

Linear::Linear(Matrix weight, Matrix bias) : weight_(std::move(weight)), bias_(std::move(bias)) {
  if (weight_.rows() <= 0 || weight_.cols() <= 0 || bias_.rows() != weight_.rows() ||
      bias_.cols() != 1) {
    throw std::invalid_argument("Linear: weight must be out x in and bias out x 1, got " +
                                std::to_string(weight_.rows()) + "x" +
                                std::to_string(weight_.cols()) + " and " +
                                std::to_string(bias_.rows()) + "x" + std::to_string(bias_.cols()));
  }
  weight_grad_.setZero(weight_.rows(), weight_.cols());
  bias_grad_.setZero(bias_.rows(), 1);
}

const Matrix& Linear::Forward(const Matrix& x) {
  RL_CHECK(x.rows() == weight_.cols())
      << Describe() << " got an input with " << x.rows() << " rows";
  input_ = &x;
  const auto out = static_cast<int>(weight_.rows());
  const auto batch = static_cast<int>(x.cols());
  output_.resize(out, batch);
  if (batch == 1) {
    internal::Gemv(weight_.data(), out, static_cast<int>(weight_.cols()), x.data(), bias_.data(),
                   fused_output_relu_, output_.data());
  } else if (internal::PreferGemm(out, batch, static_cast<int>(weight_.cols()))) {
    internal::Epilogue epilogue;
    epilogue.row_bias = bias_.data();
    epilogue.relu = fused_output_relu_;
    const internal::ConstView w = internal::View(weight_);
    if (precision_ == Precision::kBf16 &&
        internal::GemmUsesPairs(w, internal::View(x), internal::View(&output_)) &&
        UseWeightPairs()) {
      internal::GemmPackedPairs(weight_pairs_.data(), out, w.cols, internal::View(x),
                                internal::View(&output_), /*accumulate=*/false, epilogue,
                                &workspace_);
    } else {
      internal::Gemm(w, internal::View(x), internal::View(&output_), /*accumulate=*/false, epilogue,
                     &workspace_, precision_);
    }
  } else {
    output_.noalias() = weight_ * x;
    output_.colwise() += bias_.col(0);
    if (fused_output_relu_) output_ = output_.cwiseMax(0.0f);
  }
  return output_;
}

bool Linear::UseWeightPairs() {
  if (seen_version_ != weight_version_) {
    pairs_pay_ = passes_at_version_ >= 2;
    seen_version_ = weight_version_;
    passes_at_version_ = 0;
  }
  ++passes_at_version_;
  if (!weight_pairs_.empty() && pairs_version_ == weight_version_) return true;
  if (!pairs_pay_ && passes_at_version_ == 1) return false;
  const auto out = static_cast<int>(weight_.rows());
  const auto in = static_cast<int>(weight_.cols());
  weight_pairs_.resize(static_cast<size_t>(internal::PackedPairs(out, in)));
  internal::RoundIntoPairs(internal::View(weight_), weight_pairs_.data());
  pairs_version_ = weight_version_;
  return true;
}

void Linear::AccumulateParamGrads(const Matrix& grad_out) {
  RL_CHECK(input_ != nullptr) << Describe() << ": Backward() before Forward()";
  const Matrix& x = *input_;
  RL_CHECK(grad_out.rows() == weight_.rows() && grad_out.cols() == x.cols())
      << Describe() << " got an output gradient of " << grad_out.rows() << "x" << grad_out.cols()
      << " for a batch of " << x.cols();
  // dW += dY x^T.
  if (internal::PreferGemm(static_cast<int>(weight_.rows()), static_cast<int>(weight_.cols()),
                           static_cast<int>(x.cols()))) {
    internal::Gemm(internal::View(grad_out), internal::View(x).Transposed(),
                   internal::View(&weight_grad_), /*accumulate=*/true, {}, &workspace_, precision_);
  } else {
    weight_grad_.noalias() += grad_out * x.transpose();
  }
  // db += sum over the batch of dY.
  internal::AddRowSums(grad_out, bias_grad_.data());
}

void Linear::BackwardParams(const Matrix& grad_out) { AccumulateParamGrads(grad_out); }

const Matrix& Linear::Backward(const Matrix& grad_out) {
  AccumulateParamGrads(grad_out);
  // dx = W^T dY, times the derivative of a fused preceding ReLU (1 where its output x > 0).
  const Matrix& x = *input_;
  const auto out = static_cast<int>(weight_.rows());
  const auto in = static_cast<int>(weight_.cols());
  const auto batch = static_cast<int>(x.cols());
  grad_input_.resize(in, batch);
  if (internal::PreferGemm(in, batch, out)) {
    internal::Epilogue epilogue;
    if (fused_input_relu_grad_) epilogue.mask = x.data();
    internal::Gemm(internal::View(weight_).Transposed(), internal::View(grad_out),
                   internal::View(&grad_input_), /*accumulate=*/false, epilogue, &workspace_,
                   precision_);
  } else {
    grad_input_.noalias() = weight_.transpose() * grad_out;
    if (fused_input_relu_grad_) {
      grad_input_.array() = (x.array() > 0.0f).select(grad_input_.array(), 0.0f);
    }
  }
  return grad_input_;
}

std::vector<Param> Linear::Params() {
  return {{"weight", &weight_, &weight_grad_, &weight_version_}, {"bias", &bias_, &bias_grad_}};
}

std::string Linear::Describe() const {
  return "linear(" + std::to_string(weight_.cols()) + "," + std::to_string(weight_.rows()) + ")";
}

std::unique_ptr<Layer> Linear::Clone() const {
  auto copy = std::make_unique<Linear>(weight_, bias_);
  copy->precision_ = precision_;
  return copy;
}

}  // namespace rl::nn
