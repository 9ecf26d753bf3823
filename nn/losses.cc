#include "nn/losses.h"

#include <cmath>

#include "common/check.h"

namespace rl::nn {
namespace {

void CheckSizes(const char* loss, const Vector& pred, const Vector& target, const Vector* weights) {
  RL_CHECK(target.size() == pred.size())
      << loss << ": " << pred.size() << " predictions but " << target.size() << " targets";
  RL_CHECK(weights == nullptr || weights->size() == pred.size())
      << loss << ": " << pred.size() << " predictions but " << weights->size() << " weights";
}

}  // namespace

float HuberLoss(const Vector& pred, const Vector& target, Vector* grad, float delta,
                const Vector* weights) {
  CheckSizes("HuberLoss", pred, target, weights);
  const Eigen::Index n = pred.size();
  if (grad != nullptr) grad->resize(n);
  if (n == 0) return 0.0f;
  const float inv_n = 1.0f / static_cast<float>(n);
  double sum = 0.0;
  for (Eigen::Index i = 0; i < n; ++i) {
    const float e = pred[i] - target[i];
    const float abs_e = std::abs(e);
    const float w = weights != nullptr ? (*weights)[i] : 1.0f;
    const float loss = abs_e <= delta ? 0.5f * e * e : delta * (abs_e - 0.5f * delta);
    sum += static_cast<double>(w * loss);
    if (grad != nullptr) {
      const float slope = abs_e <= delta ? e : std::copysign(delta, e);
      (*grad)[i] = w * slope * inv_n;
    }
  }
  return static_cast<float>(sum / static_cast<double>(n));
}

float MseLoss(const Vector& pred, const Vector& target, Vector* grad, const Vector* weights) {
  CheckSizes("MseLoss", pred, target, weights);
  const Eigen::Index n = pred.size();
  if (grad != nullptr) grad->resize(n);
  if (n == 0) return 0.0f;
  const float inv_n = 1.0f / static_cast<float>(n);
  double sum = 0.0;
  for (Eigen::Index i = 0; i < n; ++i) {
    const float e = pred[i] - target[i];
    const float w = weights != nullptr ? (*weights)[i] : 1.0f;
    sum += static_cast<double>(w * e * e);
    if (grad != nullptr) (*grad)[i] = 2.0f * w * e * inv_n;
  }
  return static_cast<float>(sum / static_cast<double>(n));
}

}  // namespace rl::nn
