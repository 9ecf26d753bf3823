// Finite-difference helpers for gradient tests.
#pragma once

#include <cmath>
#include <functional>
#include <random>

#include <gtest/gtest.h>

#include "nn/tensor.h"

namespace rl::nn {

/// d(loss)/d(*x) by central differences: (loss(x + eps e_i) - loss(x - eps e_i)) / (2 eps) for
/// every element i of *x. `loss` reads *x; *x is restored afterwards.
inline Matrix NumericalGradient(const std::function<double()>& loss, Matrix* x, float eps = 1e-3f) {
  Matrix grad(x->rows(), x->cols());
  for (Eigen::Index i = 0; i < x->size(); ++i) {
    const float saved = x->data()[i];
    x->data()[i] = saved + eps;
    const double plus = loss();
    x->data()[i] = saved - eps;
    const double minus = loss();
    x->data()[i] = saved;
    grad.data()[i] = static_cast<float>((plus - minus) / (2.0 * static_cast<double>(eps)));
  }
  return grad;
}

/// Expects |analytic - numerical| <= atol + rtol * |numerical| element-wise.
inline void ExpectGradientsClose(const Matrix& analytic, const Matrix& numerical,
                                 const std::string& what, float rtol = 1e-2f, float atol = 1e-3f) {
  ASSERT_EQ(analytic.rows(), numerical.rows()) << what;
  ASSERT_EQ(analytic.cols(), numerical.cols()) << what;
  for (Eigen::Index i = 0; i < analytic.size(); ++i) {
    const float a = analytic.data()[i];
    const float n = numerical.data()[i];
    EXPECT_LE(std::abs(a - n), atol + rtol * std::abs(n))
        << what << " element " << i << ": analytic " << a << ", numerical " << n;
  }
}

/// A rows x cols matrix of U(-scale, scale) entries.
inline Matrix RandomMatrix(int rows, int cols, std::mt19937* rng, float scale = 1.0f) {
  std::uniform_real_distribution<float> dist(-scale, scale);
  Matrix m(rows, cols);
  for (Eigen::Index i = 0; i < m.size(); ++i) m.data()[i] = dist(*rng);
  return m;
}

/// sum(r .* m) in double: a scalar "loss" whose gradient with respect to m is r.
inline double Dot(const Matrix& r, const Matrix& m) {
  return (r.cast<double>().array() * m.cast<double>().array()).sum();
}

}  // namespace rl::nn
