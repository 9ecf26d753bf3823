#include "nn/conv2d.h"

#include <cmath>
#include <memory>
#include <random>
#include <stdexcept>
#include <string>

#include <gtest/gtest.h>

#include "tests/nn/gradient_check.h"
#include "tests/nn/kernel_paths.h"
#include "tests/nn/layer_gradient_check.h"

namespace rl::nn {
namespace {

// The geometry of one test convolution.
struct ConvCase {
  int in_channels;
  int out_channels;
  int kernel;
  int stride;
  int padding;
  int height;
  int width;

  std::string Name() const {
    return "conv2d(" + std::to_string(in_channels) + "," + std::to_string(out_channels) + "," +
           std::to_string(kernel) + "," + std::to_string(stride) + "," + std::to_string(padding) +
           "," + std::to_string(height) + "," + std::to_string(width) + ")";
  }
  Conv2d Make(std::mt19937* rng) const {
    return Conv2d(in_channels, out_channels, kernel, stride, padding, height, width, rng);
  }
};

// Direct convolution, six loops per sample, in double: output (o, oy, ox) = bias[o] + sum over
// (c, ky, kx) of weight(tap(c, ky, kx), o) * padded input (c, oy * s + ky - p, ox * s + kx - p).
Matrix NaiveConv2d(const ConvCase& g, const Matrix& weight, const Matrix& bias, const Matrix& x) {
  const int oh = (g.height + 2 * g.padding - g.kernel) / g.stride + 1;
  const int ow = (g.width + 2 * g.padding - g.kernel) / g.stride + 1;
  Matrix y(g.out_channels * oh * ow, x.cols());
  for (Eigen::Index b = 0; b < x.cols(); ++b) {
    for (int o = 0; o < g.out_channels; ++o) {
      for (int oy = 0; oy < oh; ++oy) {
        for (int ox = 0; ox < ow; ++ox) {
          double sum = bias(o, 0);
          for (int c = 0; c < g.in_channels; ++c) {
            for (int ky = 0; ky < g.kernel; ++ky) {
              for (int kx = 0; kx < g.kernel; ++kx) {
                const int iy = oy * g.stride + ky - g.padding;
                const int ix = ox * g.stride + kx - g.padding;
                if (iy < 0 || iy >= g.height || ix < 0 || ix >= g.width) continue;
                const int tap = (c * g.kernel + ky) * g.kernel + kx;
                sum +=
                    static_cast<double>(weight(tap, o)) * x((c * g.height + iy) * g.width + ix, b);
              }
            }
          }
          y((o * oh + oy) * ow + ox, b) = static_cast<float>(sum);
        }
      }
    }
  }
  return y;
}

// The tests of the computation run on every kernel path this CPU can run.
class Conv2dKernelTest : public KernelPathTest {};
RL_INSTANTIATE_KERNEL_PATHS(Conv2dKernelTest);

TEST(Conv2dTest, ComputesOutputShapesLikePyTorch) {
  std::mt19937 rng(0);
  const Conv2d nature1(4, 32, 8, 4, 0, 84, 84, &rng);
  EXPECT_EQ(nature1.output_shape(), (ImageShape{32, 20, 20}));
  EXPECT_EQ(nature1.input_size(), 28224);
  EXPECT_EQ(nature1.output_size(), 12800);
  EXPECT_EQ(Conv2d(32, 64, 4, 2, 0, 20, 20, &rng).output_shape(), (ImageShape{64, 9, 9}));
  EXPECT_EQ(Conv2d(64, 64, 3, 1, 0, 9, 9, &rng).output_shape(), (ImageShape{64, 7, 7}));
  EXPECT_EQ(Conv2d(4, 32, 8, 4, 0, 40, 40, &rng).output_shape(), (ImageShape{32, 9, 9}));
  EXPECT_EQ(Conv2d(3, 8, 3, 2, 1, 7, 10, &rng).output_shape(), (ImageShape{8, 4, 5}));
  EXPECT_EQ(Conv2d(4, 32, 8, 4, 0, 84, 84, &rng).Describe(), "conv2d(4,32,8,4,0,84,84)");
}

TEST(Conv2dTest, InitialisesWeightsAndBiasWithinOneOverSqrtFanIn) {
  std::mt19937 rng(1);
  Conv2d conv(3, 16, 5, 1, 0, 9, 9, &rng);
  const float bound = 1.0f / std::sqrt(75.0f);
  EXPECT_EQ(conv.weight().rows(), 75);
  EXPECT_EQ(conv.weight().cols(), 16);
  EXPECT_LE(conv.weight().cwiseAbs().maxCoeff(), bound);
  EXPECT_GT(conv.weight().cwiseAbs().maxCoeff(), 0.9f * bound);
  EXPECT_LE(conv.bias().cwiseAbs().maxCoeff(), bound);
  EXPECT_NEAR(conv.weight().mean(), 0.0f, 0.02f);
}

TEST_P(Conv2dKernelTest, ForwardMatchesANaiveConvolution) {
  const ConvCase cases[] = {
      {3, 5, 3, 1, 0, 7, 9},
      {2, 4, 4, 2, 1, 9, 7},
      {1, 3, 5, 3, 2, 11, 6},
      {3, 2, 1, 1, 0, 4, 5},
      {2, 3, 3, 2, 0, 5, 5},
      {4, 32, 8, 4, 0, 84, 84},
      {32, 64, 4, 2, 0, 20, 20},
      {8, 16, 3, 1, 1, 16, 16},
      {5, 7, 2, 3, 1, 8, 13},
      {64, 64, 3, 1, 0, 3, 3},
      {4, 32, 8, 4, 0, 40, 40},
      {32, 64, 4, 2, 0, 9, 9},
      // The car encoder's (CarEncoderArchitecture()): stride-2 rows of 84 and of 20 floats.
      {4, 16, 4, 2, 0, 84, 84},
      {16, 32, 4, 2, 0, 20, 20},
  };
  std::mt19937 rng(2);
  for (const ConvCase& g : cases) {
    for (int batch : {1, 3, 10}) {
      SCOPED_TRACE(g.Name() + " batch " + std::to_string(batch));
      Conv2d conv = g.Make(&rng);
      const Matrix x = RandomMatrix(conv.input_size(), batch, &rng);
      const Matrix expected = NaiveConv2d(g, conv.weight(), conv.bias(), x);
      const Matrix& y = conv.Forward(x);
      ASSERT_EQ(y.rows(), expected.rows());
      ASSERT_EQ(y.cols(), batch);
      EXPECT_LE((y - expected).cwiseAbs().maxCoeff(), 1e-4f);
    }
  }
}

TEST_P(Conv2dKernelTest, FusedReluClampsTheOutput) {
  std::mt19937 rng(3);
  const ConvCase g{2, 4, 3, 2, 1, 9, 8};
  Conv2d conv = g.Make(&rng);
  const Matrix x = RandomMatrix(conv.input_size(), 5, &rng);
  const Matrix plain = conv.Forward(x);
  ASSERT_TRUE(conv.FuseOutputRelu());
  EXPECT_EQ(Matrix(conv.Forward(x)), Matrix(plain.cwiseMax(0.0f)));
  EXPECT_LT(plain.minCoeff(), 0.0f);
}

// Checks d(sum(r .* conv(x)))/d(x, weight, bias) against central differences.
void CheckGradients(const ConvCase& g, int batch) {
  SCOPED_TRACE(g.Name() + " batch " + std::to_string(batch));
  std::mt19937 rng(static_cast<unsigned>(g.kernel * 100 + g.stride * 10 + g.padding + batch));
  Conv2d conv = g.Make(&rng);
  const Matrix x = RandomMatrix(conv.input_size(), batch, &rng);
  const Matrix r = RandomMatrix(conv.output_size(), batch, &rng);
  ExpectWeightAndBiasGradientsMatch(&conv, x, r);

  // BackwardParams() adds the same parameter gradients.
  const Matrix dw = conv.weight_grad();
  const Matrix db = conv.bias_grad();
  conv.Forward(x);
  conv.BackwardParams(r);
  EXPECT_LE((conv.weight_grad() - 2.0f * dw).cwiseAbs().maxCoeff(), 1e-4f);
  EXPECT_LE((conv.bias_grad() - 2.0f * db).cwiseAbs().maxCoeff(), 1e-4f);
}

TEST_P(Conv2dKernelTest, GradientsMatchFiniteDifferences) {
  CheckGradients({2, 3, 3, 1, 0, 5, 6}, 2);
  CheckGradients({2, 3, 3, 2, 1, 7, 6}, 3);
  CheckGradients({1, 2, 4, 2, 0, 8, 10}, 2);
  CheckGradients({3, 2, 2, 3, 2, 5, 9}, 1);
  CheckGradients({2, 2, 1, 1, 0, 3, 4}, 2);
  CheckGradients({2, 4, 3, 1, 1, 4, 4}, 2);
  CheckGradients({2, 3, 3, 3, 0, 9, 9}, 2);
  CheckGradients({1, 2, 4, 4, 0, 8, 12}, 2);
  CheckGradients({2, 2, 5, 4, 2, 9, 11}, 1);
  // Kernels that cover the whole input (one output pixel), computed as a fully connected layer.
  CheckGradients({3, 4, 3, 1, 0, 3, 3}, 3);
  CheckGradients({2, 3, 4, 2, 0, 4, 4}, 1);
}

// Batches large enough to be unfolded in several groups, the last one partial.
TEST_P(Conv2dKernelTest, GradientsAreTheSameForEveryGroupingOfTheBatch) {
  std::mt19937 rng(4);
  const ConvCase g{8, 16, 3, 1, 1, 16, 16};
  Conv2d conv = g.Make(&rng);
  const int batch = 17;
  const Matrix x = RandomMatrix(conv.input_size(), batch, &rng);
  const Matrix r = RandomMatrix(conv.output_size(), batch, &rng);
  conv.Forward(x);
  const Matrix dx = conv.Backward(r);
  const Matrix dw = conv.weight_grad();
  const Matrix db = conv.bias_grad();

  Matrix dw_sum = Matrix::Zero(dw.rows(), dw.cols());
  Matrix db_sum = Matrix::Zero(db.rows(), db.cols());
  for (int j = 0; j < batch; ++j) {
    Conv2d single = g.Make(&rng);
    single.weight() = conv.weight();
    single.bias() = conv.bias();
    const Matrix xj = x.col(j);
    single.Forward(xj);
    const Matrix dxj = single.Backward(r.col(j));
    EXPECT_LE((dxj - dx.col(j)).cwiseAbs().maxCoeff(), 1e-4f) << "sample " << j;
    dw_sum += single.weight_grad();
    db_sum += single.bias_grad();
  }
  EXPECT_LE((dw_sum - dw).cwiseAbs().maxCoeff(), 1e-3f);
  EXPECT_LE((db_sum - db).cwiseAbs().maxCoeff(), 1e-3f);
}

TEST_P(Conv2dKernelTest, FusedInputReluGradMasksWhereTheInputIsNotPositive) {
  std::mt19937 rng(5);
  for (const ConvCase& g : {ConvCase{2, 3, 3, 2, 1, 7, 7}, ConvCase{2, 3, 3, 1, 0, 5, 5},
                            ConvCase{4, 3, 3, 1, 0, 3, 3}}) {
    SCOPED_TRACE(g.Name());
    Conv2d conv = g.Make(&rng);
    const Matrix x = RandomMatrix(conv.input_size(), 4, &rng);
    const Matrix r = RandomMatrix(conv.output_size(), 4, &rng);
    conv.Forward(x);
    const Matrix plain = conv.Backward(r);
    ASSERT_TRUE(conv.FuseInputReluGrad());
    conv.Forward(x);
    const Matrix masked = conv.Backward(r);
    EXPECT_EQ(masked, Matrix((x.array() > 0.0f).select(plain, 0.0f)));
  }
}

TEST(Conv2dTest, CloneCopiesParametersWithoutGradients) {
  std::mt19937 rng(6);
  Conv2d conv(2, 3, 3, 1, 1, 5, 5, &rng);
  const Matrix x = RandomMatrix(conv.input_size(), 2, &rng);
  conv.Forward(x);
  conv.Backward(RandomMatrix(conv.output_size(), 2, &rng));
  const std::unique_ptr<Layer> copy = conv.Clone();
  auto& clone = dynamic_cast<Conv2d&>(*copy);
  EXPECT_EQ(clone.weight(), conv.weight());
  EXPECT_EQ(clone.bias(), conv.bias());
  EXPECT_EQ(clone.weight_grad().squaredNorm(), 0.0f);
  EXPECT_EQ(Matrix(clone.Forward(x)), Matrix(conv.Forward(x)));
  EXPECT_EQ(clone.Describe(), "conv2d(2,3,3,1,1,5,5)");
}

TEST(Conv2dTest, RejectsInvalidGeometry) {
  std::mt19937 rng(7);
  EXPECT_THROW(Conv2d(0, 3, 3, 1, 0, 5, 5, &rng), std::invalid_argument);
  EXPECT_THROW(Conv2d(2, 3, 3, 0, 0, 5, 5, &rng), std::invalid_argument);
  EXPECT_THROW(Conv2d(2, 3, 3, 1, -1, 5, 5, &rng), std::invalid_argument);
  EXPECT_THROW(Conv2d(2, 3, 6, 1, 0, 5, 5, &rng), std::invalid_argument);
  EXPECT_NO_THROW(Conv2d(2, 3, 6, 1, 1, 5, 5, &rng));
  try {
    Conv2d(2, 3, 9, 1, 0, 5, 8, &rng);
    ADD_FAILURE() << "no exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("conv2d(2,3,9,1,0,5,8)"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace rl::nn
