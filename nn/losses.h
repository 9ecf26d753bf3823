// Regression losses over a batch of scalar predictions (e.g. Q(s, a) of the taken actions).
//
// Both return the mean over the n elements of w_i * l_i (w_i = 1 without weights) and write
// d(mean loss)/d(pred_i) = w_i * l_i'(pred_i) / n into *grad (resized to n), ready to be scattered
// into the output gradient of a network. `grad` may be null when only the value is needed.
// `target` and `weights` must have pred.size() elements (checked). An empty batch has loss 0.
#pragma once

#include "nn/tensor.h"

namespace rl::nn {

/// Huber loss: 0.5 e^2 if |e| <= delta, else delta (|e| - 0.5 delta), with e = pred - target.
/// With delta = 1 this is PyTorch's smooth_l1_loss (beta = 1) and huber_loss, reduction "mean".
float HuberLoss(const Vector& pred, const Vector& target, Vector* grad, float delta = 1.0f,
                const Vector* weights = nullptr);

/// Squared error (pred - target)^2, PyTorch's mse_loss with reduction "mean".
float MseLoss(const Vector& pred, const Vector& target, Vector* grad,
              const Vector* weights = nullptr);

}  // namespace rl::nn
