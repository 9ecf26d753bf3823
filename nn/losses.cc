#include "nn/losses.h"

#include <cmath>
#include <utility>

#include "common/check.h"

namespace rl::nn {
namespace {

// The weighted mean of loss(e) over the batch, with e = pred - target, and its gradient
// w slope(e) / n; loss_and_slope(e) returns both.
template <class LossAndSlope>
float WeightedMean(const char* name, const Vector& pred, const Vector& target, Vector* grad,
                   const Vector* weights, LossAndSlope loss_and_slope) {
  RL_CHECK(target.size() == pred.size())
      << name << ": " << pred.size() << " predictions but " << target.size() << " targets";
  RL_CHECK(weights == nullptr || weights->size() == pred.size())
      << name << ": " << pred.size() << " predictions but " << weights->size() << " weights";
  const Eigen::Index n = pred.size();
  if (grad != nullptr) grad->resize(n);
  if (n == 0) return 0.0f;
  const float inv_n = 1.0f / static_cast<float>(n);
  double sum = 0.0;
  for (Eigen::Index i = 0; i < n; ++i) {
    const auto [loss, slope] = loss_and_slope(pred[i] - target[i]);
    const float w = weights != nullptr ? (*weights)[i] : 1.0f;
    sum += static_cast<double>(w * loss);
    if (grad != nullptr) (*grad)[i] = w * slope * inv_n;
  }
  return static_cast<float>(sum / static_cast<double>(n));
}

}  // namespace

float HuberLoss(const Vector& pred, const Vector& target, Vector* grad, float delta,
                const Vector* weights) {
  return WeightedMean("HuberLoss", pred, target, grad, weights, [delta](float e) {
    const float abs_e = std::abs(e);
    return abs_e <= delta ? std::pair{0.5f * e * e, e}
                          : std::pair{delta * (abs_e - 0.5f * delta), std::copysign(delta, e)};
  });
}

float MseLoss(const Vector& pred, const Vector& target, Vector* grad, const Vector* weights) {
  return WeightedMean("MseLoss", pred, target, grad, weights, [](float e) {
    return std::pair{e * e, 2.0f * e};
  });
}

}  // namespace rl::nn
