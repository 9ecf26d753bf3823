#include "nn/sequential.h"

#include <algorithm>
#include <stdexcept>
#include <string>
#include <utility>

#include "common/check.h"
#include "nn/activations.h"
#include "nn/linear.h"

namespace rl::nn {

Sequential::Sequential(const Sequential& other)
    : training_(other.training_), precision_(other.precision_) {
  for (const auto& layer : other.layers_) Add(layer->Clone());
}

Sequential& Sequential::operator=(const Sequential& other) {
  if (this != &other) {
    Sequential copy(other);
    *this = std::move(copy);
  }
  return *this;
}

void Sequential::Add(std::unique_ptr<Layer> layer) {
  RL_CHECK(layer != nullptr) << "Sequential::Add got a null layer";
  const int in = layer->input_size();
  if (in != 0 && output_size_ != 0 && in != output_size_) {
    throw std::invalid_argument("layer " + std::to_string(layers_.size()) + " " +
                                layer->Describe() + " expects " + std::to_string(in) +
                                " inputs but the previous layer produces " +
                                std::to_string(output_size_));
  }
  const ImageShape in_image = layer->input_shape();
  if (!in_image.empty() && !image_.empty() && in_image != image_) {
    auto str = [](const ImageShape& s) {
      return std::to_string(s.channels) + "x" + std::to_string(s.height) + "x" +
             std::to_string(s.width);
    };
    throw std::invalid_argument("layer " + std::to_string(layers_.size()) + " " +
                                layer->Describe() + " expects " + str(in_image) +
                                " images but the previous layers produce " + str(image_));
  }
  if (input_size_ == 0 && output_size_ == 0) input_size_ = in;
  if (layer->output_size() != 0) output_size_ = layer->output_size();
  // Track image shapes through element-wise and shape-preserving layers only.
  if (!layer->output_shape().empty()) {
    image_ = layer->output_shape();
  } else if (layer->output_size() != 0 && layer->output_size() != in) {
    image_ = {};
  }

  // Fuse ReLUs into the layers around them, where those support it.
  Layer* prev = layers_.empty() ? nullptr : layers_.back().get();
  auto* relu = dynamic_cast<ReLU*>(layer.get());
  fused_forward_.push_back(nullptr);
  fused_backward_.push_back(false);
  inputs_.push_back(nullptr);
  if (relu != nullptr && prev != nullptr && dynamic_cast<ReLU*>(prev) == nullptr &&
      prev->FuseOutputRelu()) {
    fused_forward_.back() = relu;
  }
  if (relu == nullptr && dynamic_cast<ReLU*>(prev) != nullptr && layer->FuseInputReluGrad()) {
    fused_backward_[layers_.size() - 1] = true;
  }
  layer->set_training(training_);
  layer->set_precision(precision_);

  const std::string prefix = std::to_string(layers_.size()) + ".";
  for (Param& p : layer->Params()) {
    RL_CHECK(p.value != nullptr && p.grad != nullptr && p.value->rows() == p.grad->rows() &&
             p.value->cols() == p.grad->cols())
        << layer->Describe() << ": parameter " << p.name << " lacks a matching gradient";
    num_params_ += p.value->size();
    p.name = prefix + p.name;
    params_.push_back(p);
  }
  for (Buffer& b : layer->Buffers()) {
    RL_CHECK(b.value != nullptr) << layer->Describe() << ": buffer " << b.name << " is null";
    num_buffers_ += b.value->size();
    buffers_.push_back({prefix + b.name, b.value});
  }
  if (!architecture_.empty()) architecture_ += ",";
  architecture_ += layer->Describe();
  layers_.push_back(std::move(layer));
}

void Sequential::set_precision(Precision precision) {
  precision_ = precision;
  for (auto& layer : layers_) layer->set_precision(precision);
}

void Sequential::set_training(bool training) {
  training_ = training;
  for (auto& layer : layers_) layer->set_training(training);
}

const Matrix& Sequential::Forward(const Matrix& x) {
  const Matrix* h = &x;
  for (size_t i = 0; i < layers_.size(); ++i) {
    inputs_[i] = h;
    h = fused_forward_[i] != nullptr ? &fused_forward_[i]->AdoptOutput(*h)
                                     : &layers_[i]->Forward(*h);
  }
  return *h;
}

const Matrix& Sequential::LayerInput(int i) const {
  if (i < 0 || i >= num_layers()) {
    throw std::out_of_range("LayerInput(" + std::to_string(i) + ") of a network of " +
                            std::to_string(num_layers()) + " layers");
  }
  const Matrix* input = inputs_[static_cast<size_t>(i)];
  if (input == nullptr) throw std::logic_error("LayerInput before the first forward pass");
  return *input;
}

const Matrix& Sequential::Backward(const Matrix& grad_out) {
  const Matrix* g = &grad_out;
  for (size_t i = layers_.size(); i-- > 0;) {
    if (!fused_backward_[i]) g = &layers_[i]->Backward(*g);
  }
  return *g;
}

void Sequential::BackwardParams(const Matrix& grad_out) {
  const Matrix* g = &grad_out;
  for (size_t i = layers_.size(); i-- > 1;) {
    if (!fused_backward_[i]) g = &layers_[i]->Backward(*g);
  }
  // A fused ReLU in front still needs its mask applied by the layer after it, so only an unfused
  // first layer can skip the input gradient.
  if (!layers_.empty() && !fused_backward_[0]) layers_[0]->BackwardParams(*g);
}

void Sequential::ZeroGrad() {
  for (Param& p : params_) p.grad->setZero();
}

void Sequential::GetFlat(std::vector<float>* out) const {
  out->resize(static_cast<size_t>(FlatSize()));
  float* dst = out->data();
  for (const Param& p : params_) {
    std::copy_n(p.value->data(), p.value->size(), dst);
    dst += p.value->size();
  }
  for (const Buffer& b : buffers_) {
    std::copy_n(b.value->data(), b.value->size(), dst);
    dst += b.value->size();
  }
}

void Sequential::SetFlat(const float* data, size_t n) {
  if (n != static_cast<size_t>(FlatSize())) {
    throw std::invalid_argument(
        "SetFlat: got " + std::to_string(n) + " floats but " + architecture_ + " has " +
        std::to_string(num_params_) + " parameters" +
        (num_buffers_ > 0 ? " and " + std::to_string(num_buffers_) + " buffer floats" : ""));
  }
  for (Param& p : params_) {
    std::copy_n(data, p.value->size(), p.value->data());
    p.MarkChanged();
    data += p.value->size();
  }
  for (Buffer& b : buffers_) {
    std::copy_n(data, b.value->size(), b.value->data());
    data += b.value->size();
  }
}

void Sequential::CopyParamsFrom(const Sequential& other) {
  RL_CHECK(architecture_ == other.architecture_)
      << "CopyParamsFrom needs the same architecture: " << architecture_ << " vs "
      << other.architecture_;
  for (size_t i = 0; i < params_.size(); ++i) {
    *params_[i].value = *other.params_[i].value;
    params_[i].MarkChanged();
  }
  for (size_t i = 0; i < buffers_.size(); ++i) *buffers_[i].value = *other.buffers_[i].value;
}

void Sequential::SoftUpdateFrom(const Sequential& other, float tau) {
  RL_CHECK(architecture_ == other.architecture_)
      << "SoftUpdateFrom needs the same architecture: " << architecture_ << " vs "
      << other.architecture_;
  for (size_t i = 0; i < params_.size(); ++i) {
    Matrix& mine = *params_[i].value;
    mine = tau * *other.params_[i].value + (1.0f - tau) * mine;
    params_[i].MarkChanged();
  }
  for (size_t i = 0; i < buffers_.size(); ++i) {
    Matrix& mine = *buffers_[i].value;
    mine = tau * *other.buffers_[i].value + (1.0f - tau) * mine;
  }
}

const Matrix& Sequential::Predict(const float* obs, int obs_size) {
  RL_CHECK(input_size_ == 0 || obs_size == input_size_)
      << "Predict got " << obs_size << " features, " << architecture_ << " takes " << input_size_;
  observation_.resize(obs_size, 1);
  std::copy_n(obs, obs_size, observation_.data());
  if (!training_ || buffers_.empty()) return Forward(observation_);
  // Only layers with buffers behave differently in evaluation mode.
  for (auto& layer : layers_) layer->set_training(false);
  const Matrix& q = Forward(observation_);
  for (auto& layer : layers_) layer->set_training(true);
  return q;
}

int Sequential::Argmax(const float* obs, int obs_size) {
  const Matrix& q = Predict(obs, obs_size);
  RL_CHECK(q.size() > 0) << "Argmax on a network without outputs";
  Eigen::Index best = 0;
  q.col(0).maxCoeff(&best);
  return static_cast<int>(best);
}

Sequential MakeMlp(int in, const std::vector<int>& hidden, int out, std::mt19937* rng) {
  Sequential net;
  int prev = in;
  for (int h : hidden) {
    net.Add(std::make_unique<Linear>(prev, h, rng));
    net.Add(std::make_unique<ReLU>());
    prev = h;
  }
  net.Add(std::make_unique<Linear>(prev, out, rng));
  return net;
}

}  // namespace rl::nn
