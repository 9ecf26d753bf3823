// Finite-difference check of a layer with a weight and a bias (Conv2d, BatchNorm2d, LayerNorm).
#pragma once

#include "tests/nn/gradient_check.h"

namespace rl::nn {

/// Checks the analytic gradients of sum(r .* layer->Forward(x)) with respect to x, the layer's
/// weight and its bias against central differences. `Layer` has Forward, Backward, weight(),
/// bias(), weight_grad() and bias_grad(). Leaves *layer with the gradients of one Backward(r) at x.
template <typename Layer>
void ExpectWeightAndBiasGradientsMatch(Layer* layer, Matrix x, const Matrix& r) {
  auto loss = [&] { return Dot(r, layer->Forward(x)); };
  layer->Forward(x);
  const Matrix dx = layer->Backward(r);
  ExpectGradientsClose(dx, NumericalGradient(loss, &x), "input");
  ExpectGradientsClose(layer->weight_grad(), NumericalGradient(loss, &layer->weight()), "weight");
  ExpectGradientsClose(layer->bias_grad(), NumericalGradient(loss, &layer->bias()), "bias");
}

}  // namespace rl::nn
