// First-order optimizers with PyTorch semantics (torch.optim.Adam and torch.optim.RMSprop with
// default flags), and global gradient-norm clipping.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "nn/tensor.h"

namespace rl::nn {

/// Updates a fixed set of parameters from their gradients. The Params (usually
/// Sequential::Params()) must outlive the optimizer. Step() does not allocate and does not zero
/// the gradients. Not thread-safe.
class Optimizer {
 public:
  virtual ~Optimizer() = default;
  Optimizer(const Optimizer&) = delete;
  Optimizer& operator=(const Optimizer&) = delete;

  /// Applies one update using the current gradients, and marks every parameter changed
  /// (Param::MarkChanged()).
  void Step();

  void set_learning_rate(float lr) { learning_rate_ = lr; }
  float learning_rate() const { return learning_rate_; }

  /// The optimizer's state, so that a restarted learner continues where it stopped: every
  /// per-parameter buffer (Adam's moments; RMSprop's averages and momentum), one after another in
  /// parameter order, each column-major, and the number of steps taken. SetState() restores what
  /// GetState() wrote for an optimizer of the same parameters and settings; it throws
  /// std::invalid_argument (state unchanged) when the size does not match or steps < 0.
  void GetState(std::vector<float>* values, int64_t* steps) const;
  void SetState(std::span<const float> values, int64_t steps);

 protected:
  /// Throws std::invalid_argument if lr < 0; checks that every Param has a same-shaped grad.
  Optimizer(std::vector<Param> params, float lr);
  const std::vector<Param>& params() const { return params_; }
  /// Subclasses name their per-parameter buffers (in GetState() order) and their step counter
  /// once, in their constructor; both must be members of the optimizer itself.
  void RegisterState(std::vector<Matrix>* buffers) { state_.push_back(buffers); }
  void RegisterStepCounter(int64_t* steps) { steps_ = steps; }
  /// The update of Step(), writing the parameters' values.
  virtual void UpdateParams() = 0;

 private:
  std::vector<Param> params_;
  float learning_rate_;
  std::vector<std::vector<Matrix>*> state_;
  int64_t* steps_ = nullptr;
};

/// Adam (Kingma & Ba) with bias correction, as torch.optim.Adam without weight decay/amsgrad:
///   m = b1 m + (1 - b1) g;  v = b2 v + (1 - b2) g^2
///   p -= lr / (1 - b1^t) * m / (sqrt(v) / sqrt(1 - b2^t) + eps)
class Adam : public Optimizer {
 public:
  /// Throws std::invalid_argument unless lr >= 0, 0 <= beta < 1 and eps >= 0.
  explicit Adam(std::vector<Param> params, float lr = 1e-3f, float beta1 = 0.9f,
                float beta2 = 0.999f, float eps = 1e-8f);
  /// Number of Step() calls so far (t in the formulas).
  int64_t step_count() const { return step_count_; }

 protected:
  void UpdateParams() override;

 private:
  float beta1_;
  float beta2_;
  float eps_;
  int64_t step_count_ = 0;
  std::vector<Matrix> m_;  // First moments, one per parameter.
  std::vector<Matrix> v_;  // Second moments.
};

/// RMSprop as torch.optim.RMSprop without weight decay:
///   s = alpha s + (1 - alpha) g^2
///   centered: a = alpha a + (1 - alpha) g;  d = sqrt(s - a^2) + eps, else d = sqrt(s) + eps
///   momentum > 0: buf = momentum buf + g / d;  p -= lr buf, else p -= lr g / d
class RmsProp : public Optimizer {
 public:
  /// Throws std::invalid_argument unless lr >= 0, 0 <= alpha <= 1, eps >= 0 and momentum >= 0.
  explicit RmsProp(std::vector<Param> params, float lr = 1e-2f, float alpha = 0.99f,
                   float eps = 1e-8f, bool centered = false, float momentum = 0.0f);

 protected:
  void UpdateParams() override;

 private:
  float alpha_;
  float eps_;
  bool centered_;
  float momentum_;
  std::vector<Matrix> square_avg_;
  std::vector<Matrix> grad_avg_;      // Only when centered.
  std::vector<Matrix> momentum_buf_;  // Only when momentum > 0.
};

/// Scales all gradients together so that their global L2 norm is at most `max_norm`: if the norm
/// exceeds it, every gradient is multiplied by max_norm / (norm + 1e-6) (as
/// torch.nn.utils.clip_grad_norm_). Returns the norm before clipping, which is NaN or Inf (and the
/// gradients are left alone) if a gradient is not finite.
float ClipGradNorm(const std::vector<Param>& params, float max_norm);

}  // namespace rl::nn
