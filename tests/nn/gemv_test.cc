#include "nn/gemv.h"

#include <random>

#include <gtest/gtest.h>

#include "nn/tensor.h"
#include "tests/nn/kernel_paths.h"

namespace rl::nn::internal {
namespace {

class GemvTest : public KernelPathTest {};
RL_INSTANTIATE_KERNEL_PATHS(GemvTest);

TEST_P(GemvTest, MatchesEigenForEveryBlockingCase) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  for (int out : {1, 2, 15, 16, 17, 33, 84, 128, 129, 300}) {
    for (int in : {1, 3, 4, 5, 120}) {
      for (bool relu : {false, true}) {
        Matrix w(out, in);
        Vector x(in), b(out);
        for (int i = 0; i < w.size(); ++i) w.data()[i] = u(rng);
        for (int i = 0; i < in; ++i) x[i] = u(rng);
        for (int i = 0; i < out; ++i) b[i] = u(rng);
        Vector expected = w * x + b;
        if (relu) expected = expected.cwiseMax(0.0f);
        // One extra element on each side catches a write outside y.
        Vector y = Vector::Constant(out + 2, 7.0f);
        Gemv(w.data(), out, in, x.data(), b.data(), relu, y.data() + 1);
        EXPECT_EQ(y[0], 7.0f);
        EXPECT_EQ(y[out + 1], 7.0f);
        for (int i = 0; i < out; ++i) {
          ASSERT_NEAR(y[i + 1], expected[i], 1e-4f) << "out " << out << " in " << in << " i " << i;
        }
      }
    }
  }
}

}  // namespace
}  // namespace rl::nn::internal
