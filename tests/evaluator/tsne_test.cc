#include "evaluator/tsne.h"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <numeric>
#include <random>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

namespace rl::evaluator {
namespace {

constexpr int kClusters = 5;
constexpr int kPerCluster = 60;
constexpr int kDims = 20;
constexpr int kNeighbours = 10;

// 5 clusters of 60 points in 20-D: centres 10 apart along the first axes, unit Gaussian noise
// (points of one cluster about 6.3 apart, of two clusters about 15.5). Point i is in cluster
// i % kClusters, so the clusters are interleaved in the input order.
Eigen::MatrixXf Clusters(uint32_t seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<float> noise(0.0f, 1.0f);
  Eigen::MatrixXf x(kDims, kClusters * kPerCluster);
  for (int i = 0; i < x.cols(); ++i) {
    for (int d = 0; d < kDims; ++d) x(d, i) = noise(rng);
    x(i % kClusters, i) += 10.0f;
  }
  return x;
}

// Indices of the k nearest other points of point i (squared Euclidean distance), nearest first.
template <class M>
std::vector<int> Nearest(const M& points, int i, int k) {
  const int n = static_cast<int>(points.cols());
  std::vector<int> order;
  std::vector<double> dist(static_cast<size_t>(n));
  for (int j = 0; j < n; ++j) {
    dist[static_cast<size_t>(j)] =
        (points.col(j).template cast<double>() - points.col(i).template cast<double>())
            .squaredNorm();
    if (j != i) order.push_back(j);
  }
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) {
    return dist[static_cast<size_t>(a)] < dist[static_cast<size_t>(b)];
  });
  order.resize(static_cast<size_t>(k));
  return order;
}

// Mean over the points of the fraction of their k nearest embedded neighbours in their cluster.
double SameClusterFraction(const Eigen::MatrixXd& y, int k) {
  double total = 0;
  for (int i = 0; i < y.cols(); ++i) {
    int same = 0;
    for (int j : Nearest(y, i, k)) same += (j % kClusters == i % kClusters) ? 1 : 0;
    total += static_cast<double>(same) / k;
  }
  return total / static_cast<double>(y.cols());
}

// Mean over the points of |kNN in the input ∩ kNN in the embedding| / k.
double NeighbourOverlap(const Eigen::MatrixXf& x, const Eigen::MatrixXd& y, int k) {
  double total = 0;
  for (int i = 0; i < x.cols(); ++i) {
    std::vector<int> a = Nearest(x, i, k), b = Nearest(y, i, k);
    std::sort(a.begin(), a.end());
    std::sort(b.begin(), b.end());
    std::vector<int> both;
    std::set_intersection(a.begin(), a.end(), b.begin(), b.end(), std::back_inserter(both));
    total += static_cast<double>(both.size()) / k;
  }
  return total / static_cast<double>(x.cols());
}

// Trustworthiness (Venna and Kaski 2001): 1 minus the penalty of embedded neighbours that are not
// input neighbours, by how far down the input ranking they are; 1 when every embedded
// neighbourhood is an input neighbourhood.
double Trustworthiness(const Eigen::MatrixXf& x, const Eigen::MatrixXd& y, int k) {
  const int n = static_cast<int>(x.cols());
  double penalty = 0;
  for (int i = 0; i < n; ++i) {
    const std::vector<int> ranking = Nearest(x, i, n - 1);  // rank r(i, j) = position + 1
    std::vector<int> rank(static_cast<size_t>(n), 0);
    for (size_t r = 0; r < ranking.size(); ++r) {
      rank[static_cast<size_t>(ranking[r])] = static_cast<int>(r) + 1;
    }
    for (int j : Nearest(y, i, k)) penalty += std::max(0, rank[static_cast<size_t>(j)] - k);
  }
  return 1.0 - 2.0 / (n * k * (2.0 * n - 3.0 * k - 1.0)) * penalty;
}

TEST(TsneTest, KeepsWellSeparatedClustersApartAndNeighboursTogether) {
  const Eigen::MatrixXf x = Clusters(11);
  std::vector<TsneProgress> steps;
  double kl = 0;
  const Eigen::MatrixXd y = Tsne(
      x, TsneConfig(), [&](const TsneProgress& p) { steps.push_back(p); }, 50, &kl);
  ASSERT_EQ(y.rows(), 2);
  ASSERT_EQ(y.cols(), x.cols());
  EXPECT_TRUE(y.allFinite());
  // Re-centred on the origin after every step.
  EXPECT_NEAR(y.row(0).mean(), 0.0, 1e-9);
  EXPECT_NEAR(y.row(1).mean(), 0.0, 1e-9);

  const double same = SameClusterFraction(y, kNeighbours);
  const double trust = Trustworthiness(x, y, kNeighbours);
  const double overlap = NeighbourOverlap(x, y, kNeighbours);
  RecordProperty("same_cluster", std::to_string(same));
  RecordProperty("trustworthiness", std::to_string(trust));
  RecordProperty("knn_overlap", std::to_string(overlap));
  EXPECT_GE(same, 0.95);
  EXPECT_GE(trust, 0.9);
  // Within a cluster the input neighbours are its noise: a map that kept the clusters but placed
  // each one's points at random would share about 9 / 59 = 0.15 of them.
  EXPECT_GE(overlap, 0.3);

  // Progress every 50 iterations and after the last; the KL divergence falls once the
  // exaggeration is over and ends where the returned one is.
  ASSERT_EQ(steps.size(), 20U);
  EXPECT_EQ(steps.front().iteration, 50);
  EXPECT_EQ(steps.back().iteration, 1000);
  EXPECT_EQ(steps.back().iterations, 1000);
  EXPECT_DOUBLE_EQ(steps.back().kl_divergence, kl);
  EXPECT_LT(kl, steps[5].kl_divergence);  // iteration 300
  EXPECT_GT(kl, 0.0);
}

TEST(TsneTest, IsDeterministicForASeedAndDiffersForAnother) {
  const Eigen::MatrixXf x = Clusters(12);
  TsneConfig c;
  c.iterations = 400;
  c.seed = 7;
  const Eigen::MatrixXd a = Tsne(x, c);
  const Eigen::MatrixXd b = Tsne(x, c);
  EXPECT_TRUE((a.array() == b.array()).all()) << "the same seed gave other bits";
  c.seed = 8;
  const Eigen::MatrixXd other = Tsne(x, c);
  EXPECT_GT((other - a).cwiseAbs().maxCoeff(), 1e-3);
  // Another start, the same clusters.
  EXPECT_GE(SameClusterFraction(other, kNeighbours), 0.95);
}

// Calls call() and returns the what() of the std::invalid_argument it throws, or "no exception"
// (any other exception goes through).
template <class Call>
std::string InvalidArgumentOf(const Call& call) {
  try {
    call();
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "no exception";
}

TEST(TsneTest, RefusesTooFewPointsTooLargeAPerplexityAndValuesThatAreNotFinite) {
  const TsneConfig c;
  EXPECT_NE(
      InvalidArgumentOf([&] { Tsne(Eigen::MatrixXf::Random(3, 4), c); }).find("at least 5 points"),
      std::string::npos);
  // Perplexity 30 needs 91 points; 90 are refused, and so is a perplexity of N or more.
  EXPECT_NE(InvalidArgumentOf([&] { Tsne(Eigen::MatrixXf::Random(3, 90), c); }).find("perplexity"),
            std::string::npos);
  TsneConfig big;
  big.perplexity = 10;
  EXPECT_THROW(Tsne(Eigen::MatrixXf::Random(3, 10), big), std::invalid_argument);
  Eigen::MatrixXf x = Eigen::MatrixXf::Random(3, 100);
  x(1, 42) = std::nanf("");
  EXPECT_NE(InvalidArgumentOf([&] { Tsne(x, c); }).find("point 42"), std::string::npos);
  x(1, 42) = INFINITY;
  EXPECT_THROW(Tsne(x, c), std::invalid_argument);
  EXPECT_THROW(Tsne(Eigen::MatrixXf::Random(3, 100), c, {}, 0), std::invalid_argument);
}

TEST(TsneTest, ConfigValidateNamesTheField) {
  EXPECT_EQ(InvalidArgumentOf([] { TsneConfig().Validate(); }), "no exception");
  // One value out of range each, and the field the error must name.
  const std::pair<const char*, void (*)(TsneConfig*)> cases[] = {
      {"perplexity", [](TsneConfig* c) { c->perplexity = 0.5; }},
      {"perplexity", [](TsneConfig* c) { c->perplexity = INFINITY; }},
      {"iterations", [](TsneConfig* c) { c->iterations = 0; }},
      {"learning_rate", [](TsneConfig* c) { c->learning_rate = -1; }},
      {"exaggeration", [](TsneConfig* c) { c->exaggeration = 0.5; }},
      {"exaggeration_iterations", [](TsneConfig* c) { c->exaggeration_iterations = -1; }},
      {"initial_momentum", [](TsneConfig* c) { c->initial_momentum = 1; }},
      {"final_momentum", [](TsneConfig* c) { c->final_momentum = -0.1; }},
      {"momentum_switch_iteration", [](TsneConfig* c) { c->momentum_switch_iteration = -5; }},
      {"min_gain", [](TsneConfig* c) { c->min_gain = 0; }},
  };
  for (size_t i = 0; i < std::size(cases); ++i) {
    const auto& [field, set_bad_value] = cases[i];
    SCOPED_TRACE(::testing::Message() << "case " << i << ": " << field);
    TsneConfig c;
    set_bad_value(&c);
    EXPECT_NE(InvalidArgumentOf([&] { c.Validate(); }).find(field), std::string::npos);
  }
}

double Entropy(const std::vector<double>& p) {
  double h = 0;
  for (double v : p) h -= v > 0 ? v * std::log(v) : 0.0;
  return h;
}

TEST(TsneTest, TheBandwidthSearchReachesTheTargetPerplexity) {
  // Squared distances from point 2 (itself at 0) to 8 others.
  const std::vector<double> d = {4.0, 1.0, 0.0, 9.0, 0.25, 2.0, 16.0, 1.0, 6.0};
  std::vector<double> p(d.size());
  for (double perplexity : {1.5, 2.0, 3.0, 5.0}) {
    const double beta = ConditionalProbabilities(d, 2, perplexity, p);
    EXPECT_GT(beta, 0.0);
    EXPECT_EQ(p[2], 0.0);
    EXPECT_NEAR(std::accumulate(p.begin(), p.end(), 0.0), 1.0, 1e-12);
    // The entropy is log(perplexity): 2^H = perplexity with H in bits.
    EXPECT_NEAR(Entropy(p), std::log(perplexity), 1e-5) << "perplexity " << perplexity;
    // A Gaussian of the returned bandwidth: p_j / p_k = exp(-beta (d_j - d_k)).
    EXPECT_NEAR(p[4] / p[0], std::exp(-beta * (0.25 - 4.0)), 1e-9 * p[4] / p[0]);
    EXPECT_DOUBLE_EQ(p[1], p[7]);
  }
  // Two neighbours at the same distance: perplexity 2 is both of them, one half each.
  std::vector<double> two(3);
  ConditionalProbabilities(std::vector<double>{7.0, 0.0, 7.0}, 1, 2.0, two);
  EXPECT_NEAR(two[0], 0.5, 1e-12);
  EXPECT_NEAR(two[2], 0.5, 1e-12);
  // By hand: two neighbours at squared distances 1 and 2 (only the difference counts) weigh 3/4
  // and 1/4 when exp(-beta) = 1/3, beta = ln 3; their perplexity is
  // exp(-(3/4) ln(3/4) - (1/4) ln(1/4)) = 1.7548 (to 4 digits).
  std::vector<double> hand(3);
  const double perplexity = std::exp(-(0.75 * std::log(0.75) + 0.25 * std::log(0.25)));
  const double beta =
      ConditionalProbabilities(std::vector<double>{2.0, 0.0, 1.0}, 1, perplexity, hand, 1e-10);
  EXPECT_NEAR(perplexity, 1.7548, 1e-4);
  EXPECT_NEAR(beta, std::log(3.0), 1e-6);
  EXPECT_NEAR(hand[2], 0.75, 1e-7);
  EXPECT_NEAR(hand[0], 0.25, 1e-7);
  // Bad calls.
  EXPECT_THROW(ConditionalProbabilities(d, 9, 2.0, p), std::invalid_argument);
  EXPECT_THROW(ConditionalProbabilities(d, 0, 0.5, p), std::invalid_argument);
  std::vector<double> short_p(3);
  EXPECT_THROW(ConditionalProbabilities(d, 0, 2.0, short_p), std::invalid_argument);
}

TEST(TsneTest, JointProbabilitiesAreSymmetricAndSumToOne) {
  const Eigen::MatrixXf x = Clusters(13);
  const Eigen::MatrixXf p = JointProbabilities(x, 20);
  const auto n = static_cast<double>(x.cols());
  EXPECT_NEAR(p.cast<double>().sum(), 1.0, 1e-5);
  EXPECT_EQ(p.diagonal().cwiseAbs().maxCoeff(), 0.0f);
  EXPECT_EQ((p - p.transpose()).cwiseAbs().maxCoeff(), 0.0f);
  EXPECT_GE(p.minCoeff(), 0.0f);
  // Every point's probabilities sum to at least 1 / 2N (its own conditional half).
  for (int i = 0; i < x.cols(); ++i) EXPECT_GE(p.col(i).sum(), 1.0 / (2.0 * n) * (1 - 1e-5));
}

TEST(TsneTest, TheGradientIsTheDerivativeOfTheKlDivergence) {
  std::mt19937 rng(21);
  std::normal_distribution<double> normal(0.0, 1.0);
  Eigen::MatrixXf x(3, 12);
  for (int i = 0; i < x.size(); ++i) x.data()[i] = static_cast<float>(normal(rng));
  const Eigen::MatrixXf p = JointProbabilities(x, 3);
  Eigen::MatrixXd y(2, 12);
  for (int i = 0; i < y.size(); ++i) y.data()[i] = normal(rng);
  Eigen::MatrixXd gradient;
  const double kl = TsneObjective(p, y, &gradient);
  EXPECT_GT(kl, 0.0);
  ASSERT_EQ(gradient.rows(), 2);
  ASSERT_EQ(gradient.cols(), 12);
  // Central differences of the KL divergence (in double); the gradient's pair sums are in float.
  const double h = 1e-5;
  for (int i = 0; i < y.size(); ++i) {
    Eigen::MatrixXd plus = y, minus = y;
    plus.data()[i] += h;
    minus.data()[i] -= h;
    const double numeric = (TsneObjective(p, plus) - TsneObjective(p, minus)) / (2 * h);
    EXPECT_NEAR(gradient.data()[i], numeric, 1e-4 + 1e-4 * std::abs(numeric)) << "coordinate " << i;
  }
  EXPECT_THROW(TsneObjective(p, Eigen::MatrixXd::Zero(2, 11)), std::invalid_argument);
}

TEST(TsneTest, IdenticalPointsAreAllowed) {
  // Ten copies of each of three points: zero distances everywhere within a group.
  Eigen::MatrixXf x(4, 30);
  for (int i = 0; i < 30; ++i) x.col(i) = Eigen::Vector4f::Constant(static_cast<float>(i % 3));
  TsneConfig c;
  c.perplexity = 5;
  c.iterations = 300;
  const Eigen::MatrixXd y = Tsne(x, c);
  ASSERT_TRUE(y.allFinite());
  // Copies end up together, the three groups apart.
  for (int i = 0; i < 30; ++i) {
    for (int j : Nearest(y, i, 9)) EXPECT_EQ(j % 3, i % 3) << "point " << i;
  }
}

}  // namespace
}  // namespace rl::evaluator
