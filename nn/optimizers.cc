#include "nn/optimizers.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>

#include "common/check.h"

namespace rl::nn {
namespace {

// Zero-initialised state tensors shaped like the parameters.
std::vector<Matrix> ZerosLike(const std::vector<Param>& params) {
  std::vector<Matrix> out;
  out.reserve(params.size());
  for (const Param& p : params) out.emplace_back(Matrix::Zero(p.value->rows(), p.value->cols()));
  return out;
}

// Optimizer steps run over each tensor in chunks of this many floats, several element-wise passes
// per chunk while it is in the L1 cache: a single pass over memory, yet vectorised by Eigen.
constexpr Eigen::Index kChunk = 1024;

// Calls f(start, length) for consecutive chunks of the tensor of `p`.
template <typename F>
void ForEachChunk(const Param& p, F&& f) {
  const Eigen::Index size = p.value->size();
  for (Eigen::Index at = 0; at < size; at += kChunk) f(at, std::min(kChunk, size - at));
}

// Elements [at, at + n) of a tensor in storage order, as an array expression.
inline auto Chunk(Matrix* m, Eigen::Index at, Eigen::Index n) {
  return Eigen::Map<Eigen::ArrayXf>(m->data() + at, n);
}
inline auto Chunk(const Matrix& m, Eigen::Index at, Eigen::Index n) {
  return Eigen::Map<const Eigen::ArrayXf>(m.data() + at, n);
}

void Require(bool ok, const std::string& what) {
  if (!ok) throw std::invalid_argument(what);
}

}  // namespace

Optimizer::Optimizer(std::vector<Param> params, float lr)
    : params_(std::move(params)), learning_rate_(lr) {
  Require(lr >= 0.0f, "learning rate must be >= 0, got " + std::to_string(lr));
  for (const Param& p : params_) {
    RL_CHECK(p.value != nullptr && p.grad != nullptr && p.value->rows() == p.grad->rows() &&
             p.value->cols() == p.grad->cols())
        << "parameter " << p.name << " needs a gradient of the same shape";
  }
}

void Optimizer::Step() {
  UpdateParams();
  for (const Param& p : params_) p.MarkChanged();
}

void Optimizer::GetState(std::vector<float>* values, int64_t* steps) const {
  values->clear();
  for (const std::vector<Matrix>* list : state_) {
    for (const Matrix& m : *list) values->insert(values->end(), m.data(), m.data() + m.size());
  }
  *steps = steps_ != nullptr ? *steps_ : 0;
}

void Optimizer::SetState(std::span<const float> values, int64_t steps) {
  size_t total = 0;
  for (const std::vector<Matrix>* list : state_) {
    for (const Matrix& m : *list) total += static_cast<size_t>(m.size());
  }
  Require(values.size() == total, "optimizer state of " + std::to_string(values.size()) +
                                      " values, expected " + std::to_string(total));
  Require(steps >= 0, "optimizer state with a negative step count");
  const float* at = values.data();
  for (std::vector<Matrix>* list : state_) {
    for (Matrix& m : *list) {
      std::copy(at, at + m.size(), m.data());
      at += m.size();
    }
  }
  if (steps_ != nullptr) *steps_ = steps;
}

Adam::Adam(std::vector<Param> params, float lr, float beta1, float beta2, float eps)
    : Optimizer(std::move(params), lr), beta1_(beta1), beta2_(beta2), eps_(eps) {
  Require(beta1 >= 0.0f && beta1 < 1.0f,
          "Adam beta1 must be in [0, 1), got " + std::to_string(beta1));
  Require(beta2 >= 0.0f && beta2 < 1.0f,
          "Adam beta2 must be in [0, 1), got " + std::to_string(beta2));
  Require(eps >= 0.0f, "Adam eps must be >= 0, got " + std::to_string(eps));
  m_ = ZerosLike(this->params());
  v_ = ZerosLike(this->params());
  RegisterState(&m_);
  RegisterState(&v_);
  RegisterStepCounter(&step_count_);
}

void Adam::UpdateParams() {
  ++step_count_;
  const double t = static_cast<double>(step_count_);
  const auto bias_correction1 = static_cast<float>(1.0 - std::pow(double{beta1_}, t));
  const auto bias_correction2 = static_cast<float>(1.0 - std::pow(double{beta2_}, t));
  const float step_size = learning_rate() / bias_correction1;
  const float inv_sqrt_bc2 = 1.0f / std::sqrt(bias_correction2);
  const std::vector<Param>& ps = params();
  for (size_t i = 0; i < ps.size(); ++i) {
    ForEachChunk(ps[i], [&](Eigen::Index at, Eigen::Index n) {
      const auto g = Chunk(*ps[i].grad, at, n);
      auto m = Chunk(&m_[i], at, n);
      auto v = Chunk(&v_[i], at, n);
      m = beta1_ * m + (1.0f - beta1_) * g;
      v = beta2_ * v + (1.0f - beta2_) * g.square();
      Chunk(ps[i].value, at, n) -= step_size * m / (v.sqrt() * inv_sqrt_bc2 + eps_);
    });
  }
}

RmsProp::RmsProp(std::vector<Param> params, float lr, float alpha, float eps, bool centered,
                 float momentum)
    : Optimizer(std::move(params), lr),
      alpha_(alpha),
      eps_(eps),
      centered_(centered),
      momentum_(momentum) {
  Require(alpha >= 0.0f && alpha <= 1.0f,
          "RmsProp alpha must be in [0, 1], got " + std::to_string(alpha));
  Require(eps >= 0.0f, "RmsProp eps must be >= 0, got " + std::to_string(eps));
  Require(momentum >= 0.0f, "RmsProp momentum must be >= 0, got " + std::to_string(momentum));
  square_avg_ = ZerosLike(this->params());
  if (centered_) grad_avg_ = ZerosLike(this->params());
  if (momentum_ > 0.0f) momentum_buf_ = ZerosLike(this->params());
  RegisterState(&square_avg_);
  RegisterState(&grad_avg_);
  RegisterState(&momentum_buf_);
}

void RmsProp::UpdateParams() {
  const float lr = learning_rate();
  const std::vector<Param>& ps = params();
  for (size_t i = 0; i < ps.size(); ++i) {
    ForEachChunk(ps[i], [&](Eigen::Index at, Eigen::Index n) {
      const auto g = Chunk(*ps[i].grad, at, n);
      auto s = Chunk(&square_avg_[i], at, n);
      auto p = Chunk(ps[i].value, at, n);
      s = alpha_ * s + (1.0f - alpha_) * g.square();
      // The step g / denom, through the momentum buffer when there is one.
      const auto step = [&](const auto& denom) {
        if (momentum_ > 0.0f) {
          auto buf = Chunk(&momentum_buf_[i], at, n);
          buf = momentum_ * buf + g / denom;
          p -= lr * buf;
        } else {
          p -= lr * g / denom;
        }
      };
      if (centered_) {
        auto a = Chunk(&grad_avg_[i], at, n);
        a = alpha_ * a + (1.0f - alpha_) * g;
        // s - a^2 is a variance; clamp the rounding error that can make it slightly negative.
        step((s - a.square()).max(0.0f).sqrt() + eps_);
      } else {
        step(s.sqrt() + eps_);
      }
    });
  }
}

float ClipGradNorm(const std::vector<Param>& params, float max_norm) {
  double sum_sq = 0.0;
  for (const Param& p : params) sum_sq += static_cast<double>(p.grad->squaredNorm());
  const auto norm = static_cast<float>(std::sqrt(sum_sq));
  if (norm > max_norm) {
    const float scale = max_norm / (norm + 1e-6f);
    for (const Param& p : params) *p.grad *= scale;
  }
  return norm;
}

}  // namespace rl::nn
