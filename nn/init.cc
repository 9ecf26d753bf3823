#include "nn/init.h"

namespace rl::nn {

void FillUniform(float bound, std::mt19937* rng, Matrix* m) {
  // The top 24 bits of one draw give a float in [0, 1) exactly.
  constexpr float kScale = 1.0f / 16777216.0f;
  float* data = m->data();
  for (Eigen::Index i = 0; i < m->size(); ++i) {
    const float u = static_cast<float>((*rng)() >> 8) * kScale;
    data[i] = (2.0f * u - 1.0f) * bound;
  }
}

}  // namespace rl::nn
