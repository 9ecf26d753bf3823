// Parameter initialisation helpers.
#pragma once

#include <random>

#include "nn/tensor.h"

namespace rl::nn {

/// Fills `m` with independent samples of U(-bound, bound), in storage order. Uses only the raw
/// 32-bit outputs of `rng` (not std::uniform_real_distribution), so the values are the same with
/// every standard library for a given seed.
void FillUniform(float bound, std::mt19937* rng, Matrix* m);

}  // namespace rl::nn
