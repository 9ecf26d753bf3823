// ActionValueNet: a Q(s, a) network, the critic of TD3 (Fujimoto et al. 2018), built from three
// Sequentials:
//
//   obs ---> obs_branch ------+
//                             +-- concat [features; action features] ---> head ---> Q (1 x batch)
//   act ---> action_branch ---+
//
// An empty branch is the identity: the author's TD3 critic is head([s; a]) with both branches
// empty; the TD3 CarRacing article's critic has a CNN obs branch, a Linear-ReLU action branch and
// a small head. Backward() gives the gradient with respect to the action input, which the actor's
// update follows (dQ/da), and with respect to the observation input.
//
// Architecture string: "<obs_branch>|<action_branch>|<head>" (empty parts empty), read back by
// BuildActionValueNet. Parameters are the obs branch's, then the action branch's, then the head's,
// named "obs.<i>.<name>", "act.<i>.<name>" and "head.<i>.<name>". Copying deep-copies (as
// Sequential). Buffers as in Sequential: the flat vector holds all parameters, then all buffers.
// Not thread-safe.
#pragma once

#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include "nn/sequential.h"
#include "nn/tensor.h"

namespace rl::nn {

class ActionValueNet {
 public:
  ActionValueNet() = default;
  // Deep copies (the parts are copied; nothing of the last Forward/Backward is).
  ActionValueNet(const ActionValueNet& other);
  ActionValueNet& operator=(const ActionValueNet& other);
  ActionValueNet(ActionValueNet&&) noexcept = default;
  ActionValueNet& operator=(ActionValueNet&&) noexcept = default;
  ~ActionValueNet() = default;
  /// Throws std::invalid_argument when the parts do not chain: the head's input must be the obs
  /// branch's output (obs_size when empty) plus the action branch's output (action_size when
  /// empty), its output 1; a non-empty branch's input must be obs_size or action_size.
  ActionValueNet(Sequential obs_branch, Sequential action_branch, Sequential head, int obs_size,
                 int action_size);

  /// Q for a batch: obs is obs_size x n, act is action_size x n; returns 1 x n, valid until the
  /// next call. Both inputs must stay alive and unchanged until Backward().
  const Matrix& Forward(const Matrix& obs, const Matrix& act);
  /// Given d(loss)/dQ (1 x n) of the last Forward(): ADDS every parameter gradient, and computes
  /// grad_obs() and grad_action().
  void Backward(const Matrix& grad_q);
  /// As Backward() but without grad_obs() (the obs branch computes parameter gradients only);
  /// grad_action() is still computed.
  void BackwardParams(const Matrix& grad_q);
  /// d(loss)/d(obs) and d(loss)/d(act) of the last Backward (grad_obs: not after BackwardParams).
  const Matrix& grad_obs() const { return *grad_obs_; }
  const Matrix& grad_action() const { return *grad_action_; }

  void ZeroGrad();
  std::vector<Param> Params();
  std::vector<Buffer> Buffers();
  void set_training(bool training);
  /// The arithmetic of the three parts' products (nn/precision.h); copies keep it.
  void set_precision(Precision precision);
  std::string Architecture() const;
  int64_t FlatSize() const;
  void GetFlat(std::vector<float>* out) const;
  /// Throws std::invalid_argument if n != FlatSize().
  void SetFlat(const float* data, size_t n);
  /// Same architecture required (checked).
  void CopyParamsFrom(const ActionValueNet& other);
  /// this = tau * other + (1 - tau) * this for every parameter and buffer (Polyak averaging).
  void SoftUpdateFrom(const ActionValueNet& other, float tau);

  int obs_size() const { return obs_size_; }
  int action_size() const { return action_size_; }
  Sequential& obs_branch() { return obs_branch_; }
  Sequential& action_branch() { return action_branch_; }
  Sequential& head() { return head_; }

 private:
  void BackwardImpl(const Matrix& grad_q, bool obs_gradient);
  // The three parts, in parameter order.
  std::vector<Sequential*> Parts();
  std::vector<const Sequential*> Parts() const;

  Sequential obs_branch_, action_branch_, head_;
  int obs_size_ = 0;
  int action_size_ = 0;
  int features_ = 0;         // rows of the obs part of the concatenation
  int action_features_ = 0;  // rows of the action part
  const Matrix* obs_ = nullptr;
  const Matrix* act_ = nullptr;
  Matrix joined_, grad_features_, grad_action_features_;
  const Matrix* grad_obs_ = nullptr;
  const Matrix* grad_action_ = nullptr;
};

/// Builds an ActionValueNet from its architecture string (see above) for obs_size and
/// action_size inputs, drawing parameters from `rng` (obs branch, action branch, head). Throws
/// std::invalid_argument naming the problem.
ActionValueNet BuildActionValueNet(const std::string& arch, int obs_size, int action_size,
                                   std::mt19937* rng);

}  // namespace rl::nn
