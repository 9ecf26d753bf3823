#include "evaluator/tsne.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>

namespace rl::evaluator {
namespace {

std::string Str(double v) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%g", v);
  return buf;
}

void CheckPoints(const Eigen::Ref<const Eigen::MatrixXf>& x, double perplexity) {
  const Eigen::Index n = x.cols();
  if (n < kTsneMinPoints) {
    throw std::invalid_argument("t-SNE needs at least " + std::to_string(kTsneMinPoints) +
                                " points, got " + std::to_string(n));
  }
  if (x.rows() < 1) throw std::invalid_argument("t-SNE points need at least 1 dimension");
  if (!(perplexity >= 1.0) || !(3.0 * perplexity <= static_cast<double>(n - 1))) {
    throw std::invalid_argument(
        "perplexity must be in [1, (N - 1) / 3] = [1, " + Str(static_cast<double>(n - 1) / 3.0) +
        "] for N = " + std::to_string(n) + " points, got " + Str(perplexity));
  }
  if (!x.allFinite()) {
    for (Eigen::Index j = 0; j < n; ++j) {
      if (!x.col(j).allFinite()) {
        throw std::invalid_argument("t-SNE point " + std::to_string(j) +
                                    " has a value that is not finite");
      }
    }
  }
}

// Columns of the distance blocks: a block's products are N x kBlock doubles.
constexpr Eigen::Index kBlock = 256;

// Two N(0, 1) draws by the Box-Muller transform, so that the initial points are the same bits
// with any standard library.
void Normal2(std::mt19937_64* rng, double* a, double* b) {
  constexpr double kTwoPi = 6.283185307179586;
  // Uniform in (0, 1]: 53 random bits.
  const double u1 = (static_cast<double>((*rng)() >> 11) + 1.0) * 0x1.0p-53;
  const double u2 = static_cast<double>((*rng)() >> 11) * 0x1.0p-53;
  const double r = std::sqrt(-2.0 * std::log(u1));
  *a = r * std::cos(kTwoPi * u2);
  *b = r * std::sin(kTwoPi * u2);
}

// The pass over the pairs i < j of one gradient step, in float (the O(N^2) part). With
// w_ij = (1 + |y_i - y_j|^2)^-1 and Z = sum_{k != l} w_kl,
//   dC/dy_i = 4 [sum_j p_ij w_ij (y_i - y_j) - (1 / Z) sum_j w_ij^2 (y_i - y_j)]:
// both sums (attract, repel; set here) and Z (returned) come out of one pass, each pair visited
// once and its terms added to both of its points. p is column-major N x N.
double PairPass(const Eigen::MatrixXf& p, const float* y0, const float* y1, float* attract0,
                float* attract1, float* repel0, float* repel1) {
  const Eigen::Index n = p.cols();
  std::fill_n(attract0, n, 0.0f);
  std::fill_n(attract1, n, 0.0f);
  std::fill_n(repel0, n, 0.0f);
  std::fill_n(repel1, n, 0.0f);
  double z = 0;
  for (Eigen::Index i = 0; i + 1 < n; ++i) {
    const float yi0 = y0[i], yi1 = y1[i];
    const float* pi = p.col(i).data();
    float zi = 0, a0 = 0, a1 = 0, r0 = 0, r1 = 0;
#pragma omp simd reduction(+ : zi, a0, a1, r0, r1)
    for (Eigen::Index j = i + 1; j < n; ++j) {
      const float dx = yi0 - y0[j];
      const float dy = yi1 - y1[j];
      const float w = 1.0f / (1.0f + dx * dx + dy * dy);
      const float pw = pi[j] * w;
      const float ww = w * w;
      zi += w;
      a0 += pw * dx;
      a1 += pw * dy;
      r0 += ww * dx;
      r1 += ww * dy;
      attract0[j] -= pw * dx;
      attract1[j] -= pw * dy;
      repel0[j] -= ww * dx;
      repel1[j] -= ww * dy;
    }
    attract0[i] += a0;
    attract1[i] += a1;
    repel0[i] += r0;
    repel1[i] += r1;
    z += zi;
  }
  return 2.0 * z;  // both orders of every pair
}

// sum_{i < j} p_ij log p_ij (0 log 0 = 0): the constant part of the KL divergence.
double HalfPLogP(const Eigen::MatrixXf& p) {
  double sum = 0;
  for (Eigen::Index i = 0; i + 1 < p.cols(); ++i) {
    const auto pi = p.col(i).tail(p.cols() - 1 - i).array().cast<double>();
    sum += (pi > 0).select(pi * pi.log(), 0.0).sum();
  }
  return sum;
}

// KL(P || Q) of the points (y0, y1) = sum_{i != j} p_ij log(p_ij / q_ij), q_ij = w_ij / Z:
// 2 [sum_{i<j} p_ij log p_ij + sum_{i<j} p_ij log(1 + |y_i - y_j|^2)] + log Z. half_p_log_p is
// HalfPLogP(p); w is a scratch array of N. One logarithm per pair: in float for Tsne()'s reports
// (fast), in double for TsneObjective() (precise enough for finite differences).
template <class Scalar>
double KlDivergence(const Eigen::MatrixXf& p, double half_p_log_p,
                    const Eigen::Array<Scalar, Eigen::Dynamic, 1>& y0,
                    const Eigen::Array<Scalar, Eigen::Dynamic, 1>& y1,
                    Eigen::Array<Scalar, Eigen::Dynamic, 1>* w) {
  const Eigen::Index n = p.cols();
  double z = 0, cross = 0;
  for (Eigen::Index i = 0; i + 1 < n; ++i) {
    const Eigen::Index m = n - 1 - i;
    // 1 / w_ij
    w->head(m) = Scalar(1) + (y0[i] - y0.tail(m)).square() + (y1[i] - y1.tail(m)).square();
    z += w->head(m).inverse().sum();
    cross += (p.col(i).tail(m).array().template cast<Scalar>() * w->head(m).log()).sum();
  }
  return 2.0 * (half_p_log_p + cross) + std::log(2.0 * z);
}

}  // namespace

void TsneConfig::Validate() const {
  auto fail = [](const std::string& field, const std::string& rule, double got) {
    throw std::invalid_argument("t-SNE " + field + " must be " + rule + ", got " + Str(got));
  };
  if (!(perplexity >= 1.0) || !std::isfinite(perplexity)) {
    fail("perplexity", "finite and at least 1", perplexity);
  }
  if (iterations < 1) fail("iterations", "at least 1", iterations);
  if (!(learning_rate >= 0.0) || !std::isfinite(learning_rate)) {
    fail("learning_rate", "finite and positive, or 0 (N / exaggeration)", learning_rate);
  }
  if (!(exaggeration >= 1.0) || !std::isfinite(exaggeration)) {
    fail("exaggeration", "finite and at least 1", exaggeration);
  }
  if (exaggeration_iterations < 0) {
    fail("exaggeration_iterations", "at least 0", exaggeration_iterations);
  }
  if (!(initial_momentum >= 0.0 && initial_momentum < 1.0)) {
    fail("initial_momentum", "in [0, 1)", initial_momentum);
  }
  if (!(final_momentum >= 0.0 && final_momentum < 1.0)) {
    fail("final_momentum", "in [0, 1)", final_momentum);
  }
  if (momentum_switch_iteration < 0) {
    fail("momentum_switch_iteration", "at least 0", momentum_switch_iteration);
  }
  if (!(min_gain > 0.0) || !std::isfinite(min_gain)) {
    fail("min_gain", "finite and positive", min_gain);
  }
}

double ConditionalProbabilities(std::span<const double> sq_distances, int self, double perplexity,
                                std::span<double> p, double tolerance) {
  const auto n = static_cast<Eigen::Index>(sq_distances.size());
  if (p.size() != sq_distances.size()) {
    throw std::invalid_argument("ConditionalProbabilities: " + std::to_string(p.size()) +
                                " outputs for " + std::to_string(n) + " distances");
  }
  if (n < 2 || self < 0 || self >= n) {
    throw std::invalid_argument("ConditionalProbabilities: point " + std::to_string(self) + " of " +
                                std::to_string(n) + " (need at least 2 points)");
  }
  if (!(perplexity >= 1.0)) {
    throw std::invalid_argument("ConditionalProbabilities: perplexity must be at least 1, got " +
                                Str(perplexity));
  }
  const Eigen::Map<const Eigen::ArrayXd> d(sq_distances.data(), n);
  Eigen::Map<Eigen::ArrayXd> out(p.data(), n);
  // Distances relative to the nearest neighbour: the same probabilities, and the largest term
  // of the sum is exp(0) = 1, so the sum never underflows.
  const Eigen::Index after = n - self - 1;
  double nearest = std::numeric_limits<double>::infinity();
  double total = 0;
  if (self > 0) {
    nearest = std::min(nearest, d.head(self).minCoeff());
    total += d.head(self).sum();
  }
  if (after > 0) {
    nearest = std::min(nearest, d.tail(after).minCoeff());
    total += d.tail(after).sum();
  }
  const double mean_gap = total / static_cast<double>(n - 1) - nearest;
  const double target = std::log(perplexity);

  // Writes exp(-beta (d - nearest)) into out (0 at self) and returns the entropy of the
  // normalised distribution; *sum receives the normalisation.
  auto entropy = [&](double beta, double* sum) {
    double s = 0, weighted = 0;
    auto part = [&](Eigen::Index start, Eigen::Index count) {
      if (count == 0) return;
      const auto gap = d.segment(start, count) - nearest;
      out.segment(start, count) = (-beta * gap).exp();
      s += out.segment(start, count).sum();
      weighted += (out.segment(start, count) * gap).sum();
    };
    part(0, self);
    part(self + 1, after);
    out[self] = 0;
    *sum = s;
    return std::log(s) + beta * weighted / s;
  };

  double beta = mean_gap > 0 && std::isfinite(1.0 / mean_gap) ? 1.0 / mean_gap : 1.0;
  double lo = 0, hi = 0;
  bool has_lo = false, has_hi = false;
  double best_beta = beta, best_gap = std::numeric_limits<double>::infinity();
  for (int step = 0; step < 200; ++step) {
    double sum = 0;
    const double h = entropy(beta, &sum);
    const double gap = h - target;
    if (std::abs(gap) < best_gap) {
      best_gap = std::abs(gap);
      best_beta = beta;
    }
    if (std::abs(gap) < tolerance) break;
    if (gap > 0) {  // too flat: narrow the Gaussian
      lo = beta;
      has_lo = true;
      beta = has_hi ? (beta + hi) / 2 : beta * 2;
    } else {
      hi = beta;
      has_hi = true;
      beta = has_lo ? (beta + lo) / 2 : beta / 2;
    }
  }
  double sum = 0;
  entropy(best_beta, &sum);
  out /= sum;
  return best_beta;
}

Eigen::MatrixXf JointProbabilities(const Eigen::Ref<const Eigen::MatrixXf>& x, double perplexity) {
  CheckPoints(x, perplexity);
  const Eigen::Index n = x.cols();
  // Centred, in double: |x_i - x_j|^2 = |x_i|^2 + |x_j|^2 - 2 x_i.x_j loses less to cancellation.
  Eigen::MatrixXd xc = x.cast<double>();
  const Eigen::VectorXd mean = xc.rowwise().mean();
  xc.colwise() -= mean;
  const Eigen::VectorXd norms = xc.colwise().squaredNorm().transpose();

  // Conditional probabilities, column i = P_.|i, block by block of columns.
  Eigen::MatrixXf p(n, n);
  Eigen::MatrixXd gram(n, std::min(kBlock, n));
  Eigen::VectorXd dist(n), cond(n);
  for (Eigen::Index start = 0; start < n; start += kBlock) {
    const Eigen::Index cols = std::min(kBlock, n - start);
    gram.leftCols(cols).noalias() = xc.transpose() * xc.middleCols(start, cols);
    for (Eigen::Index c = 0; c < cols; ++c) {
      const Eigen::Index i = start + c;
      dist = (norms.array() + norms[i] - 2.0 * gram.col(c).array()).max(0.0);
      ConditionalProbabilities({dist.data(), static_cast<size_t>(n)}, static_cast<int>(i),
                               perplexity, {cond.data(), static_cast<size_t>(n)});
      p.col(i) = cond.cast<float>();
    }
  }
  // Symmetrise: p_ij = (p_j|i + p_i|j) / 2N.
  const double scale = 1.0 / (2.0 * static_cast<double>(n));
  for (Eigen::Index i = 0; i < n; ++i) {
    p(i, i) = 0;
    for (Eigen::Index j = i + 1; j < n; ++j) {
      const auto v = static_cast<float>((static_cast<double>(p(j, i)) + p(i, j)) * scale);
      p(j, i) = v;
      p(i, j) = v;
    }
  }
  return p;
}

Eigen::MatrixXd Tsne(const Eigen::Ref<const Eigen::MatrixXf>& x, const TsneConfig& config,
                     const std::function<void(const TsneProgress&)>& progress, int progress_every,
                     double* kl_divergence) {
  config.Validate();
  if (progress_every < 1) {
    throw std::invalid_argument("t-SNE progress_every must be at least 1, got " +
                                std::to_string(progress_every));
  }
  const Eigen::MatrixXf p = JointProbabilities(x, config.perplexity);
  const Eigen::Index n = x.cols();
  const double learning_rate = config.learning_rate > 0
                                   ? config.learning_rate
                                   : static_cast<double>(n) / config.exaggeration;

  // Initial points from N(0, 1e-4 I).
  Eigen::ArrayXd y0(n), y1(n);
  std::mt19937_64 rng(config.seed);
  for (Eigen::Index i = 0; i < n; ++i) {
    double a = 0, b = 0;
    Normal2(&rng, &a, &b);
    y0[i] = 1e-2 * a;
    y1[i] = 1e-2 * b;
  }

  // Per-point sums of the gradient's two parts (float, for the pair pass), the update, the gains.
  Eigen::ArrayXf yf0(n), yf1(n), attract0(n), attract1(n), repel0(n), repel1(n);
  Eigen::ArrayXd update0 = Eigen::ArrayXd::Zero(n), update1 = Eigen::ArrayXd::Zero(n);
  Eigen::ArrayXd gain0 = Eigen::ArrayXd::Ones(n), gain1 = Eigen::ArrayXd::Ones(n);
  Eigen::ArrayXd grad0(n), grad1(n);
  Eigen::ArrayXf w(n);  // scratch of the KL divergence
  const double half_p_log_p = HalfPLogP(p);
  auto kl = [&] {
    yf0 = y0.cast<float>();
    yf1 = y1.cast<float>();
    return KlDivergence(p, half_p_log_p, yf0, yf1, &w);
  };

  for (int it = 0; it < config.iterations; ++it) {
    const double exaggeration = it < config.exaggeration_iterations ? config.exaggeration : 1.0;
    const double momentum =
        it < config.momentum_switch_iteration ? config.initial_momentum : config.final_momentum;

    // The gradient (exaggerated attraction, repulsion).
    yf0 = y0.cast<float>();
    yf1 = y1.cast<float>();
    const double z = PairPass(p, yf0.data(), yf1.data(), attract0.data(), attract1.data(),
                              repel0.data(), repel1.data());
    grad0 = 4.0 * (exaggeration * attract0.cast<double>() - repel0.cast<double>() / z);
    grad1 = 4.0 * (exaggeration * attract1.cast<double>() - repel1.cast<double>() / z);

    // Adaptive gains: grow where the gradient turned against the last update, else shrink.
    gain0 = ((grad0 > 0) != (update0 > 0)).select(gain0 + 0.2, gain0 * 0.8).max(config.min_gain);
    gain1 = ((grad1 > 0) != (update1 > 0)).select(gain1 + 0.2, gain1 * 0.8).max(config.min_gain);
    update0 = momentum * update0 - learning_rate * gain0 * grad0;
    update1 = momentum * update1 - learning_rate * gain1 * grad1;
    y0 += update0;
    y1 += update1;
    y0 -= y0.mean();
    y1 -= y1.mean();

    const bool last = it + 1 == config.iterations;
    if (progress && ((it + 1) % progress_every == 0 || last)) {
      progress({it + 1, config.iterations, kl()});
    }
  }
  if (kl_divergence != nullptr) *kl_divergence = kl();

  Eigen::MatrixXd y(2, n);
  y.row(0) = y0.matrix().transpose();
  y.row(1) = y1.matrix().transpose();
  return y;
}

double TsneObjective(const Eigen::MatrixXf& p, const Eigen::MatrixXd& y,
                     Eigen::MatrixXd* gradient) {
  const Eigen::Index n = p.cols();
  if (p.rows() != n || y.rows() != 2 || y.cols() != n || n < 2) {
    throw std::invalid_argument("TsneObjective: P of " + std::to_string(p.rows()) + " x " +
                                std::to_string(n) + " and points of " + std::to_string(y.rows()) +
                                " x " + std::to_string(y.cols()));
  }
  const Eigen::ArrayXf yf0 = y.row(0).transpose().array().cast<float>();
  const Eigen::ArrayXf yf1 = y.row(1).transpose().array().cast<float>();
  const Eigen::ArrayXd y0 = y.row(0).transpose().array(), y1 = y.row(1).transpose().array();
  Eigen::ArrayXd w(n);
  const double kl = KlDivergence(p, HalfPLogP(p), y0, y1, &w);
  if (gradient != nullptr) {
    Eigen::ArrayXf attract0(n), attract1(n), repel0(n), repel1(n);
    const double z = PairPass(p, yf0.data(), yf1.data(), attract0.data(), attract1.data(),
                              repel0.data(), repel1.data());
    gradient->resize(2, n);
    gradient->row(0) =
        (4.0 * (attract0.cast<double>() - repel0.cast<double>() / z)).matrix().transpose();
    gradient->row(1) =
        (4.0 * (attract1.cast<double>() - repel1.cast<double>() / z)).matrix().transpose();
  }
  return kl;
}

}  // namespace rl::evaluator
