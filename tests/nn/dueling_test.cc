#include "nn/dueling.h"

#include <memory>
#include <random>
#include <stdexcept>
#include <string>

#include <gtest/gtest.h>

#include "tests/nn/gradient_check.h"

namespace rl::nn {
namespace {

TEST(DuelingTest, OutputIsValuePlusAdvantageMinusMeanAdvantage) {
  std::mt19937 rng(1);
  Dueling head(6, 10, 4, &rng);
  const Matrix x = RandomMatrix(6, 5, &rng);
  const Matrix q = head.Forward(x);
  ASSERT_EQ(q.rows(), 4);
  ASSERT_EQ(q.cols(), 5);
  // Recompute both streams with unfused copies of the sub-layers.
  auto relu = [](const Matrix& m) { return Matrix(m.cwiseMax(0.0f)); };
  const Matrix v = head.value_out().weight() * relu((head.value_hidden().weight() * x).colwise() +
                                                    head.value_hidden().bias().col(0)) +
                   Matrix::Constant(1, 5, head.value_out().bias()(0, 0));
  Matrix a = head.advantage_out().weight() * relu((head.advantage_hidden().weight() * x).colwise() +
                                                  head.advantage_hidden().bias().col(0));
  a.colwise() += head.advantage_out().bias().col(0);
  for (int j = 0; j < 5; ++j) {
    for (int i = 0; i < 4; ++i) {
      EXPECT_NEAR(q(i, j), v(0, j) + a(i, j) - a.col(j).mean(), 1e-5f) << i << "," << j;
    }
    // The advantages are centred, so the mean Q value is V.
    EXPECT_NEAR(q.col(j).mean(), v(0, j), 1e-5f);
  }
}

TEST(DuelingTest, GradientsMatchFiniteDifferences) {
  std::mt19937 rng(2);
  Dueling head(5, 7, 3, &rng);
  Matrix x = RandomMatrix(5, 4, &rng);
  const Matrix r = RandomMatrix(3, 4, &rng);
  auto loss = [&] { return Dot(r, head.Forward(x)); };
  head.Forward(x);
  const Matrix dx = head.Backward(r);
  ExpectGradientsClose(dx, NumericalGradient(loss, &x), "input");
  for (const Param& p : head.Params()) {
    const Matrix analytic = *p.grad;
    ExpectGradientsClose(analytic, NumericalGradient(loss, p.value), p.name);
  }
}

TEST(DuelingTest, NamesItsParametersLikeAPyTorchStateDict) {
  std::mt19937 rng(3);
  Dueling head(3136, 512, 7, &rng);
  const std::vector<Param> params = head.Params();
  ASSERT_EQ(params.size(), 8u);
  EXPECT_EQ(params[0].name, "value.0.weight");
  EXPECT_EQ(params[3].name, "value.2.bias");
  EXPECT_EQ(params[6].name, "advantage.2.weight");
  int64_t count = 0;
  for (const Param& p : params) count += p.value->size();
  EXPECT_EQ(count, (3136 * 512 + 512) + (512 + 1) + (3136 * 512 + 512) + (512 * 7 + 7));
  EXPECT_EQ(head.Describe(), "dueling(3136,512,7)");
  EXPECT_EQ(head.input_size(), 3136);
  EXPECT_EQ(head.output_size(), 7);
  EXPECT_THROW(Dueling(3, 0, 2, &rng), std::invalid_argument);
}

TEST(DuelingTest, CloneGivesTheSameOutputs) {
  std::mt19937 rng(4);
  Dueling head(4, 6, 3, &rng);
  const Matrix x = RandomMatrix(4, 3, &rng);
  const std::unique_ptr<Layer> clone = head.Clone();
  EXPECT_EQ(Matrix(clone->Forward(x)), Matrix(head.Forward(x)));
}

}  // namespace
}  // namespace rl::nn
