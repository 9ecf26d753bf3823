#include "nn/sequential.h"

#include <algorithm>
#include <charconv>
#include <stdexcept>
#include <utility>

#include "common/check.h"
#include "nn/activations.h"
#include "nn/linear.h"

namespace rl::nn {

Sequential::Sequential(const Sequential& other) {
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
  if (input_size_ == 0 && output_size_ == 0) input_size_ = in;
  if (layer->output_size() != 0) output_size_ = layer->output_size();

  // Fuse ReLUs into neighbouring Linear layers.
  Layer* prev = layers_.empty() ? nullptr : layers_.back().get();
  auto* relu = dynamic_cast<ReLU*>(layer.get());
  auto* linear = dynamic_cast<Linear*>(layer.get());
  fused_forward_.push_back(nullptr);
  fused_backward_.push_back(false);
  if (auto* prev_linear = dynamic_cast<Linear*>(prev); relu != nullptr && prev_linear != nullptr) {
    prev_linear->set_fused_output_relu(true);
    fused_forward_.back() = relu;
  }
  if (linear != nullptr && dynamic_cast<ReLU*>(prev) != nullptr) {
    linear->set_fused_input_relu_grad(true);
    fused_backward_[layers_.size() - 1] = true;
  }

  const std::string prefix = std::to_string(layers_.size()) + ".";
  for (Param& p : layer->Params()) {
    RL_CHECK(p.value != nullptr && p.grad != nullptr && p.value->rows() == p.grad->rows() &&
             p.value->cols() == p.grad->cols())
        << layer->Describe() << ": parameter " << p.name << " lacks a matching gradient";
    num_params_ += p.value->size();
    params_.push_back({prefix + p.name, p.value, p.grad});
  }
  if (!architecture_.empty()) architecture_ += ",";
  architecture_ += layer->Describe();
  layers_.push_back(std::move(layer));
}

const Matrix& Sequential::Forward(const Matrix& x) {
  const Matrix* h = &x;
  for (size_t i = 0; i < layers_.size(); ++i) {
    h = fused_forward_[i] != nullptr ? &fused_forward_[i]->AdoptOutput(*h)
                                     : &layers_[i]->Forward(*h);
  }
  return *h;
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
  out->resize(static_cast<size_t>(num_params_));
  float* dst = out->data();
  for (const Param& p : params_) {
    std::copy_n(p.value->data(), p.value->size(), dst);
    dst += p.value->size();
  }
}

void Sequential::SetFlat(const float* data, size_t n) {
  if (n != static_cast<size_t>(num_params_)) {
    throw std::invalid_argument("SetFlat: got " + std::to_string(n) + " floats but " +
                                architecture_ + " has " + std::to_string(num_params_) +
                                " parameters");
  }
  for (Param& p : params_) {
    std::copy_n(data, p.value->size(), p.value->data());
    data += p.value->size();
  }
}

void Sequential::CopyParamsFrom(const Sequential& other) {
  RL_CHECK(architecture_ == other.architecture_)
      << "CopyParamsFrom needs the same architecture: " << architecture_ << " vs "
      << other.architecture_;
  for (size_t i = 0; i < params_.size(); ++i) *params_[i].value = *other.params_[i].value;
}

void Sequential::SoftUpdateFrom(const Sequential& other, float tau) {
  RL_CHECK(architecture_ == other.architecture_)
      << "SoftUpdateFrom needs the same architecture: " << architecture_ << " vs "
      << other.architecture_;
  for (size_t i = 0; i < params_.size(); ++i) {
    Matrix& mine = *params_[i].value;
    mine = tau * *other.params_[i].value + (1.0f - tau) * mine;
  }
}

const Matrix& Sequential::Predict(const float* obs, int obs_size) {
  RL_CHECK(input_size_ == 0 || obs_size == input_size_)
      << "Predict got " << obs_size << " features, " << architecture_ << " takes " << input_size_;
  observation_.resize(obs_size, 1);
  std::copy_n(obs, obs_size, observation_.data());
  return Forward(observation_);
}

int Sequential::Argmax(const float* obs, int obs_size) {
  const Matrix& q = Predict(obs, obs_size);
  RL_CHECK(q.size() > 0) << "Argmax on a network without outputs";
  Eigen::Index best = 0;
  q.col(0).maxCoeff(&best);
  return static_cast<int>(best);
}

namespace {

// Throws the error of BuildFromArchitecture for `arch`.
[[noreturn]] void ArchError(const std::string& arch, const std::string& what) {
  throw std::invalid_argument("architecture '" + arch + "': " + what);
}

// One parsed layer: "name" or "name(arg,...)".
struct LayerSpec {
  std::string name;
  std::vector<std::string> args;
  bool has_parens = false;
};

std::string Trim(const std::string& s) {
  const size_t first = s.find_first_not_of(" \t");
  if (first == std::string::npos) return "";
  const size_t last = s.find_last_not_of(" \t");
  return s.substr(first, last - first + 1);
}

// Splits `arch` at the commas that are not inside parentheses.
std::vector<LayerSpec> ParseArchitecture(const std::string& arch) {
  std::vector<std::string> parts;
  std::string current;
  int depth = 0;
  for (char ch : arch) {
    if (ch == '(') ++depth;
    if (ch == ')' && --depth < 0) ArchError(arch, "unbalanced ')'");
    if (ch == ',' && depth == 0) {
      parts.push_back(current);
      current.clear();
    } else {
      current += ch;
    }
  }
  if (depth != 0) ArchError(arch, "unbalanced '('");
  parts.push_back(current);

  std::vector<LayerSpec> specs;
  for (size_t i = 0; i < parts.size(); ++i) {
    const std::string part = Trim(parts[i]);
    if (part.empty()) ArchError(arch, "layer " + std::to_string(i) + " is empty");
    LayerSpec spec;
    const size_t open = part.find('(');
    spec.name = Trim(part.substr(0, open));
    if (open != std::string::npos) {
      spec.has_parens = true;
      if (part.back() != ')') {
        ArchError(arch, "layer " + std::to_string(i) + " '" + part + "' has text after ')'");
      }
      std::string inner = part.substr(open + 1, part.size() - open - 2);
      if (!Trim(inner).empty()) {
        size_t start = 0;
        while (true) {
          const size_t comma = inner.find(',', start);
          spec.args.push_back(Trim(inner.substr(start, comma - start)));
          if (comma == std::string::npos) break;
          start = comma + 1;
        }
      }
    }
    specs.push_back(std::move(spec));
  }
  return specs;
}

int ParsePositiveInt(const std::string& arch, const std::string& layer, const std::string& s) {
  int value = 0;
  const char* end = s.data() + s.size();
  const auto [ptr, ec] = std::from_chars(s.data(), end, value);
  if (s.empty() || ec != std::errc() || ptr != end || value <= 0) {
    ArchError(arch, "layer '" + layer + "': '" + s + "' is not a positive integer");
  }
  return value;
}

}  // namespace

Sequential BuildFromArchitecture(const std::string& arch, std::mt19937* rng) {
  if (Trim(arch).empty()) ArchError(arch, "no layers");
  Sequential net;
  const std::vector<LayerSpec> specs = ParseArchitecture(arch);
  for (size_t i = 0; i < specs.size(); ++i) {
    const LayerSpec& spec = specs[i];
    const std::string where = "layer " + std::to_string(i) + " '" + spec.name + "'";
    std::unique_ptr<Layer> layer;
    if (spec.name == "linear") {
      if (spec.args.size() != 2) ArchError(arch, where + " needs linear(in,out)");
      layer = std::make_unique<Linear>(ParsePositiveInt(arch, spec.name, spec.args[0]),
                                       ParsePositiveInt(arch, spec.name, spec.args[1]), rng);
    } else if (spec.name == "relu" || spec.name == "tanh") {
      if (spec.has_parens) ArchError(arch, where + " takes no arguments");
      if (spec.name == "relu") {
        layer = std::make_unique<ReLU>();
      } else {
        layer = std::make_unique<Tanh>();
      }
    } else {
      ArchError(arch, "unknown " + where + " (known: linear(in,out), relu, tanh)");
    }
    try {
      net.Add(std::move(layer));
    } catch (const std::invalid_argument& e) {
      ArchError(arch, e.what());
    }
  }
  return net;
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
