// t-SNE (van der Maaten and Hinton 2008, "Visualizing Data using t-SNE"), exact O(N^2) version,
// embedding N points in 2-D: the evaluator's map of a network's last hidden layer (Mnih et al.
// 2015, Figure 4).
//
//   1. For every point i, Gaussian conditional probabilities
//        p_j|i = exp(-beta_i |x_i - x_j|^2) / sum_{k != i} exp(-beta_i |x_i - x_k|^2),
//      beta_i = 1 / (2 sigma_i^2) found by binary search so that the entropy of P_i is
//      log(perplexity) (natural logarithms: the perplexity 2^H of the paper, H in bits).
//   2. Joint probabilities p_ij = (p_j|i + p_i|j) / 2N.
//   3. 2-D points y_i drawn from N(0, 1e-4 I) with a seeded generator; similarities with one
//      degree of freedom, q_ij = (1 + |y_i - y_j|^2)^-1 / sum_{k != l} (1 + |y_k - y_l|^2)^-1.
//   4. Gradient descent on KL(P || Q), dC/dy_i = 4 sum_j (p_ij - q_ij)(y_i - y_j)
//      (1 + |y_i - y_j|^2)^-1, with momentum (0.5, then 0.8 from iteration 250), early
//      exaggeration (p_ij x 12 for the first 250 iterations) and per-parameter adaptive gains (the
//      "delta-bar-delta" rule of Jacobs 1988 in the paper's implementation: a gain grows by 0.2
//      while the gradient's sign differs from the last update's, else shrinks by x0.8, never below
//      0.01). The embedding is re-centred on the origin after every step.
//
// Cost: O(N^2 D) for the distances (matrix products in blocks of 256 points), O(N^2) per
// iteration (one pass over the N (N - 1) / 2 pairs, vectorised, in float). Measured (Release,
// -march=native, one thread, on the 2-core development machine while a learning run used one
// core): N = 2000 points of 512 dimensions, 1000 iterations, 0.63 s of CPU time and 0.66 to 0.69 s
// of wall time (0.16 s for P, 0.47 s for the iterations); 1.2 to 1.6 s of wall time when a build
// also ran; 0.96 s for 3136 dimensions (a Nature CNN's features). A progress report (its KL
// divergence, in float) costs about as much as two iterations. Memory: one N x N float matrix (P,
// 16 MB for N = 2000), the points in double (N D doubles) and an N x 256 block of products while
// P is made; nothing is allocated inside the iterations, progress reports included.
//
// Deterministic: the same input, config and seed give the same output bits on one build (no
// threads; Eigen's vectorised sums have a fixed order for a given build).
#pragma once

#include <cstdint>
#include <functional>
#include <span>

#include "nn/tensor.h"

namespace rl::evaluator {

/// The least number of points Tsne() accepts.
inline constexpr int kTsneMinPoints = 5;

/// Settings of Tsne(); the defaults are the paper's, but for the learning rate, which the paper
/// sets to 100 (adapted by the gains): by default N / exaggeration (Belkina et al. 2019), 167 for
/// N = 2000, since a fixed rate of 100 or 200 throws a few dozen points apart (the exaggerated
/// attractions overshoot) and converges slowly for many thousands.
struct TsneConfig {
  double perplexity = 30;    // effective number of neighbours; at most (N - 1) / 3
  int iterations = 1000;     // gradient steps
  double learning_rate = 0;  // eta; 0: N / exaggeration
  double exaggeration = 12;  // p_ij multiplied by this for the first exaggeration_iterations
  int exaggeration_iterations = 250;
  double initial_momentum = 0.5;  // before momentum_switch_iteration
  double final_momentum = 0.8;    // from momentum_switch_iteration on
  int momentum_switch_iteration = 250;
  double min_gain = 0.01;  // floor of the adaptive gains
  uint64_t seed = 1;       // of the initial points

  /// Throws std::invalid_argument naming the field: perplexity < 1 or not finite, iterations < 1,
  /// learning rate < 0 or not finite (0 is the default, N / exaggeration), exaggeration < 1 or not
  /// finite, exaggeration or momentum switch iterations < 0, a momentum outside [0, 1), min gain <=
  /// 0 or not finite.
  void Validate() const;
};

/// What Tsne() reports while it runs and returns.
struct TsneProgress {
  int iteration = 0;         // gradient steps done
  int iterations = 0;        // of this many
  double kl_divergence = 0;  // KL(P || Q) of the current points, with the true P (no exaggeration)
};

/// Runs t-SNE on the N points of `x` (one point per column, D x N, D >= 1) and returns their 2-D
/// embedding, 2 x N (column i is point i). Throws std::invalid_argument (before any work) for an
/// invalid config, N < kTsneMinPoints, a perplexity above (N - 1) / 3 (every point needs about
/// 3 x perplexity neighbours; this also refuses perplexity >= N), or a value of x that is not
/// finite. Identical points are allowed. `progress`, when set, is called every
/// `progress_every` iterations (>= 1) and after the last one, with the KL divergence (an extra
/// O(N^2) pass each time; without a callback none is computed); an exception it throws
/// propagates out of Tsne() (that is how a caller aborts). `*kl_divergence`, when not null,
/// receives the final KL divergence.
Eigen::MatrixXd Tsne(const Eigen::Ref<const Eigen::MatrixXf>& x, const TsneConfig& config,
                     const std::function<void(const TsneProgress&)>& progress = {},
                     int progress_every = 50, double* kl_divergence = nullptr);

/// Step 1 for one point: given the squared distances from point i to every point
/// (`sq_distances`, N values; entry `self` is ignored), writes p_j|i into `p` (N values, p[self]
/// = 0) and returns beta_i. Binary search on beta (doubling or halving until the target is
/// bracketed, then bisection) until the entropy is within `tolerance` nats of log(perplexity),
/// at most 200 steps; when no beta reaches it (all distances equal) the closest is kept. Throws
/// std::invalid_argument when the sizes differ, self is out of range, N < 2 or perplexity < 1.
/// O(N) per step; no allocation.
double ConditionalProbabilities(std::span<const double> sq_distances, int self, double perplexity,
                                std::span<double> p, double tolerance = 1e-5);

/// Steps 1 and 2: the symmetric joint probabilities P (N x N, zero diagonal, summing to 1) of the
/// points of `x` (D x N), with the checks of Tsne().
Eigen::MatrixXf JointProbabilities(const Eigen::Ref<const Eigen::MatrixXf>& x, double perplexity);

/// The cost Tsne() minimises, KL(P || Q), of the 2 x N points `y` for the joint probabilities `p`
/// (N x N, as JointProbabilities gives), and when `gradient` is not null its gradient (2 x N)
/// 4 sum_j (p_ij - q_ij)(y_i - y_j)(1 + |y_i - y_j|^2)^-1, computed as Tsne() computes it (the
/// pair sums in float; the KL divergence here in double, Tsne()'s reports in float). Throws
/// std::invalid_argument for mismatched sizes. O(N^2); allocates O(N).
double TsneObjective(const Eigen::MatrixXf& p, const Eigen::MatrixXd& y,
                     Eigen::MatrixXd* gradient = nullptr);

}  // namespace rl::evaluator
