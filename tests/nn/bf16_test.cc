// bf16 products (nn/precision.h) on every kernel path: the AVX512_BF16 kernels where the CPU has
// them, the emulation elsewhere. Each is compared with the bf16 reference (inputs rounded in C++,
// sums in double) within the sharp bound of its sums' rounding, and with the exact fp32 product
// within the error bf16 implies (tests/nn/kernel_paths.h gives both bounds and why).
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "nn/conv2d.h"
#include "nn/dueling.h"
#include "nn/gemm.h"
#include "nn/linear.h"
#include "nn/optimizers.h"
#include "nn/presets.h"
#include "nn/sequential.h"
#include "tests/nn/gradient_check.h"
#include "tests/nn/kernel_paths.h"

namespace rl::nn {
namespace {

uint32_t Bits(float x) {
  uint32_t b = 0;
  std::memcpy(&b, &x, sizeof(b));
  return b;
}
float FromBits(uint32_t b) {
  float x = 0;
  std::memcpy(&x, &b, sizeof(x));
  return x;
}

TEST(Bf16RoundingTest, RoundsToNearestEvenAndKeepsSpecialValues) {
  EXPECT_EQ(RoundToBf16(1.0f), 1.0f);
  EXPECT_EQ(RoundToBf16(-3.5f), -3.5f);
  // Near 1 bfloat16 values are 2^-7 apart: below half way down, above up, ties to the even one.
  EXPECT_EQ(RoundToBf16(1.0f + std::ldexp(1.0f, -9)), 1.0f);
  EXPECT_EQ(RoundToBf16(1.0f + std::ldexp(1.0f, -8) + std::ldexp(1.0f, -20)),
            1.0f + std::ldexp(1.0f, -7));
  EXPECT_EQ(RoundToBf16(1.0f + std::ldexp(1.0f, -8)), 1.0f);  // tie, 1 is even
  EXPECT_EQ(RoundToBf16(1.0f + 3 * std::ldexp(1.0f, -8)), 1.0f + std::ldexp(1.0f, -6));  // tie
  // Denormals become zeros of their sign; the largest floats round up to infinity.
  EXPECT_EQ(Bits(RoundToBf16(1e-40f)), 0U);
  EXPECT_EQ(Bits(RoundToBf16(-1e-40f)), 0x80000000U);
  EXPECT_EQ(RoundToBf16(std::numeric_limits<float>::max()), std::numeric_limits<float>::infinity());
  EXPECT_EQ(RoundToBf16(-std::numeric_limits<float>::infinity()),
            -std::numeric_limits<float>::infinity());
  EXPECT_TRUE(std::isnan(RoundToBf16(std::numeric_limits<float>::quiet_NaN())));
  EXPECT_TRUE(std::isnan(RoundToBf16(FromBits(0x7F800001U))));  // a NaN whose top bits are 0
  // The smallest normal float is a bfloat16 too.
  EXPECT_EQ(RoundToBf16(std::numeric_limits<float>::min()), std::numeric_limits<float>::min());
}

TEST(PrecisionTest, ParsesAndNamesBothPrecisions) {
  EXPECT_EQ(ParsePrecision("fp32"), Precision::kFp32);
  EXPECT_EQ(ParsePrecision("bf16"), Precision::kBf16);
  EXPECT_STREQ(PrecisionName(Precision::kBf16), "bf16");
  EXPECT_STREQ(PrecisionName(Precision::kFp32), "fp32");
  EXPECT_THROW(ParsePrecision("fp16"), std::invalid_argument);
}

TEST(KernelsTest, ReportsThePathsAndRefusesUnknownOnes) {
  const std::vector<std::string> all = KernelPaths();
  const std::vector<std::string> runnable = RunnableKernelPaths();
  ASSERT_EQ(all.size(), 3U);
  ASSERT_FALSE(runnable.empty());
  // The automatic choice is the fastest runnable path, unless RL_KERNELS asks for another.
  const char* env = std::getenv("RL_KERNELS");
  if (env != nullptr && std::string(env) != "auto" && std::string(env) != "") {
    EXPECT_EQ(KernelPath(), env);
  } else {
    EXPECT_EQ(KernelPath(), runnable.front());
  }
  std::printf(
      "kernel paths this CPU runs: %s (CPU: %s); in use: %s\n",
      [&] {
        std::string s;
        for (const std::string& p : runnable) s += (s.empty() ? "" : ", ") + p;
        return s;
      }()
          .c_str(),
      CpuFeatureSummary().c_str(), KernelPath().c_str());
  try {
    SetKernelPath("sse2");
    ADD_FAILURE() << "an unknown path was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("unknown kernel path 'sse2'"), std::string::npos)
        << e.what();
  }
}

TEST(KernelsTest, RefusesAPathThisCpuCannotRun) {
  const std::vector<std::string> runnable = RunnableKernelPaths();
  std::string missing;
  for (const std::string& p : KernelPaths()) {
    if (std::find(runnable.begin(), runnable.end(), p) == runnable.end()) missing = p;
  }
  if (missing.empty()) GTEST_SKIP() << "this CPU runs every path (" << CpuFeatureSummary() << ")";
  const std::string before = KernelPath();
  try {
    SetKernelPath(missing);
    ADD_FAILURE() << "path " << missing << " was accepted on a CPU without it";
  } catch (const std::invalid_argument& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("needs"), std::string::npos) << what;
    EXPECT_NE(what.find("it can run: " + runnable.front()), std::string::npos) << what;
  }
  EXPECT_EQ(KernelPath(), before);
  // bf16 products still run, emulated.
  EXPECT_FALSE(NativeBf16());
}

class Bf16GemmTest : public KernelPathTest {};
RL_INSTANTIATE_KERNEL_PATHS(Bf16GemmTest);

// Gemm in bf16 over every combination of transposed operands, transposed output, accumulation,
// row and column bias, against the bf16 reference (sharp bound) and the exact product (bf16
// bound). The bound scale of an entry adds |bias| and |start| to sum |a| |b|.
void CheckBf16Gemm(int m, int n, int k) {
  std::mt19937 rng(static_cast<unsigned>(m * 7919 + n * 131 + k));
  const GemmOperands o(m, n, k, &rng);
  const Matrix reference = Bf16Product(o.a, o.b);
  const Matrix exact = (o.a.cast<double>() * o.b.cast<double>()).cast<float>();
  const Matrix abs_product = AbsProduct(o.a, o.b);
  ForEachGemmMode(
      o, Precision::kBf16,
      [&](int mode, const Matrix& got, const Matrix& offset, const Matrix& offset_scale) {
        const Matrix scale = abs_product + offset_scale;
        EXPECT_LE(WorstBoundRatio(got, reference + offset, scale, SharpBf16Bound(k)), 1.0)
            << m << "x" << k << " * " << k << "x" << n << " mode " << mode
            << " against the reference";
        EXPECT_LE(WorstBoundRatio(got, exact + offset, scale, Bf16Bound(k)), 1.0)
            << m << "x" << k << " * " << k << "x" << n << " mode " << mode << " against fp32";
      });
}

TEST_P(Bf16GemmTest, MatchesTheReferenceOnEveryLayout) {
  for (const auto& [m, n, k] : {std::array<int, 3>{16, 8, 2}, std::array<int, 3>{17, 9, 1},
                                std::array<int, 3>{33, 17, 33}, std::array<int, 3>{48, 8, 256},
                                std::array<int, 3>{49, 25, 300}, std::array<int, 3>{84, 120, 128},
                                std::array<int, 3>{100, 3, 7}, std::array<int, 3>{130, 64, 513}}) {
    CheckBf16Gemm(m, n, k);
  }
}

// The fused ReLU and ReLU-backward mask, on full and ragged panels and several slices of k.
TEST_P(Bf16GemmTest, AppliesReluAndMask) {
  for (const auto& [m, n, k] : {std::array<int, 3>{48, 16, 300}, std::array<int, 3>{30, 17, 40}}) {
    std::mt19937 rng(static_cast<unsigned>(m + n + k));
    internal::GemmWorkspace workspace;
    const Matrix a = RandomMatrix(m, k, &rng);
    const Matrix b = RandomMatrix(k, n, &rng);
    const Matrix mask = RandomMatrix(m, n, &rng);
    const Matrix reference = Bf16Product(a, b);
    const Matrix scale = AbsProduct(a, b);
    internal::Epilogue relu;
    relu.relu = true;
    Matrix c(m, n);
    internal::Gemm(internal::View(a), internal::View(b), internal::View(&c), false, relu,
                   &workspace, Precision::kBf16);
    EXPECT_LE(WorstBoundRatio(c, reference.cwiseMax(0.0f), scale, SharpBf16Bound(k)), 1.0);
    internal::Epilogue masked;
    masked.mask = mask.data();
    internal::Gemm(internal::View(a), internal::View(b), internal::View(&c), false, masked,
                   &workspace, Precision::kBf16);
    const Matrix want = (mask.array() > 0.0f).select(reference, 0.0f);
    EXPECT_LE(WorstBoundRatio(c, want, scale, SharpBf16Bound(k)), 1.0);
  }
}

// With one operand the identity, each result is one rounded input: the kernel's conversions
// (every packing layout) equal RoundToBf16 bit for bit, ties and denormals included.
TEST_P(Bf16GemmTest, RoundsItsInputsExactlyAsRoundToBf16) {
  const int size = 48;
  std::mt19937 rng(3);
  Matrix values = RandomMatrix(size, size, &rng, 100.0f);
  // Ties (a 1 in bit 15 and zeros below) of odd and even neighbours, and denormals.
  for (int i = 0; i < size; ++i) {
    values(i, 0) = FromBits(0x3F808000U + (static_cast<uint32_t>(i) << 16));
    values(i, 1) = (i % 2 == 0 ? 1.0f : -1.0f) * 1e-39f * static_cast<float>(i + 1);
  }
  const Matrix identity = Matrix::Identity(size, size);
  const Matrix rounded = RoundedToBf16(values);
  internal::GemmWorkspace workspace;
  for (int mode = 0; mode < 4; ++mode) {
    const bool values_left = (mode & 1) != 0;
    const bool transposed = (mode & 2) != 0;
    const Matrix values_t = values.transpose();
    const internal::ConstView v =
        transposed ? internal::View(values_t).Transposed() : internal::View(values);
    Matrix c(size, size);
    if (values_left) {
      internal::Gemm(v, internal::View(identity), internal::View(&c), false, {}, &workspace,
                     Precision::kBf16);
    } else {
      internal::Gemm(internal::View(identity), v, internal::View(&c), false, {}, &workspace,
                     Precision::kBf16);
    }
    for (Eigen::Index i = 0; i < c.size(); ++i) {
      ASSERT_EQ(Bits(c.data()[i]) & 0x7FFFFFFFU, Bits(rounded.data()[i]) & 0x7FFFFFFFU)
          << "entry " << i << " of " << values.data()[i] << ", mode " << mode;
    }
  }
}

// A left operand packed by the caller in panels of PackedPanelRows(kBf16) rows.
TEST_P(Bf16GemmTest, PrepackedLeftOperandMatchesTheReference) {
  for (const auto& [m, n, k] :
       {std::array<int, 3>{1, 5, 3}, std::array<int, 3>{49, 64, 576},
        std::array<int, 3>{400, 32, 256}, std::array<int, 3>{30, 13, 301}}) {
    std::mt19937 rng(static_cast<unsigned>(m * 31 + n * 7 + k));
    internal::GemmWorkspace workspace;
    const Matrix a = RandomMatrix(m, k, &rng);
    const Matrix b = RandomMatrix(k, n, &rng);
    const Matrix col_bias = RandomMatrix(n, 1, &rng);
    const int rows = internal::PackedPanelRows(Precision::kBf16);
    const int panels = (m + rows - 1) / rows;
    // Rows past m hold garbage, which must not reach c.
    std::vector<float> packed(static_cast<size_t>(panels) * rows * k, 1e30f);
    for (int i = 0; i < m; ++i) {
      for (int p = 0; p < k; ++p) {
        packed[(static_cast<size_t>(i / rows) * k + p) * rows + i % rows] = a(i, p);
      }
    }
    internal::Epilogue epilogue;
    epilogue.col_bias = col_bias.data();
    Matrix c(m, n);
    internal::GemmPacked(packed.data(), m, k, internal::View(b), internal::View(&c), false,
                         epilogue, &workspace, Precision::kBf16);
    Matrix want = Bf16Product(a, b);
    want.rowwise() += col_bias.col(0).transpose();
    const Matrix scale = AbsProduct(a, b) + Matrix::Ones(m, 1) * col_bias.cwiseAbs().transpose();
    EXPECT_LE(WorstBoundRatio(c, want, scale, SharpBf16Bound(k)), 1.0) << m << "x" << n << "x" << k;
  }
}

// A left operand packed by the caller in bf16 pairs (GemmPackedPairs()), where the CPU has them.
TEST_P(Bf16GemmTest, LeftOperandInBf16PairsMatchesTheReference) {
  if (!NativeBf16()) GTEST_SKIP() << "bf16 pairs are for paths with AVX512_BF16";
  for (const auto& [m, n, k] : {std::array<int, 3>{1, 5, 3}, std::array<int, 3>{400, 32, 256},
                                std::array<int, 3>{81, 64, 513}}) {
    std::mt19937 rng(static_cast<unsigned>(m * 31 + n * 7 + k));
    internal::GemmWorkspace workspace;
    const Matrix a = RandomMatrix(m, k, &rng);
    const Matrix b = RandomMatrix(k, n, &rng);
    const int rows = internal::PackedPanelRows(Precision::kBf16);
    const int steps = (k + 1) / 2;
    std::vector<uint32_t> pairs(static_cast<size_t>(internal::PackedPairs(m, k)), 0xFFFFFFFFU);
    for (int i = 0; i < m; ++i) {
      for (int q = 0; q < steps; ++q) {
        const uint32_t even = Bits(RoundToBf16(a(i, 2 * q))) >> 16;
        const uint32_t odd = 2 * q + 1 < k ? Bits(RoundToBf16(a(i, 2 * q + 1))) >> 16 : 0;
        pairs[(static_cast<size_t>(i / rows) * steps + q) * rows + i % rows] = even | odd << 16;
      }
    }
    Matrix c(m, n);
    internal::GemmPackedPairs(pairs.data(), m, k, internal::View(b), internal::View(&c), false, {},
                              &workspace);
    EXPECT_LE(WorstBoundRatio(c, Bf16Product(a, b), AbsProduct(a, b), SharpBf16Bound(k)), 1.0)
        << m << "x" << n << "x" << k;
  }
}

// Products the kernel leaves in fp32 (a few rows): as exact as the fp32 kernel's.
TEST_P(Bf16GemmTest, SmallProductsStayFp32) {
  std::mt19937 rng(9);
  internal::GemmWorkspace workspace;
  const Matrix a = RandomMatrix(3, 200, &rng);
  const Matrix b = RandomMatrix(200, 64, &rng);
  Matrix c(3, 64);
  internal::Gemm(internal::View(a), internal::View(b), internal::View(&c), false, {}, &workspace,
                 Precision::kBf16);
  const Matrix exact = (a.cast<double>() * b.cast<double>()).cast<float>();
  EXPECT_LE(WorstBoundRatio(c, exact, AbsProduct(a, b), 202 * std::ldexp(1.0, -24)), 1.0);
}

// Both bounds would catch a wrong kernel on the shapes above: a sum that misses its largest
// product breaks the sharp bound, and pairs multiplied with the wrong partners (the halves of
// each pair swapped) break the bf16 bound.
TEST(Bf16BoundTest, CatchesAWrongKernel) {
  for (const auto& [m, n, k] : {std::array<int, 3>{16, 8, 2}, std::array<int, 3>{33, 17, 33},
                                std::array<int, 3>{130, 64, 513}}) {
    std::mt19937 rng(static_cast<unsigned>(m * 7919 + n * 131 + k));
    const Matrix a = RoundedToBf16(RandomMatrix(m, k, &rng));
    const Matrix b = RoundedToBf16(RandomMatrix(k, n, &rng));
    const Matrix reference = Bf16Product(a, b);
    const Matrix scale = AbsProduct(a, b);
    Matrix missing = reference;
    Matrix swapped = Matrix::Zero(m, n);
    for (int j = 0; j < n; ++j) {
      for (int i = 0; i < m; ++i) {
        int largest = 0;
        for (int p = 0; p < k; ++p) {
          if (std::abs(a(i, p) * b(p, j)) > std::abs(a(i, largest) * b(largest, j))) largest = p;
          const int partner = p % 2 == 0 ? std::min(p + 1, k - 1) : p - 1;
          swapped(i, j) += a(i, p) * b(partner, j);
        }
        missing(i, j) -= a(i, largest) * b(largest, j);
      }
    }
    EXPECT_GT(WorstBoundRatio(missing, reference, scale, SharpBf16Bound(k)), 1.0) << k;
    EXPECT_GT(WorstBoundRatio(swapped, reference, scale, Bf16Bound(k)), 1.0) << k;
  }
}

// The convolution geometries of the unit tests and of the networks.
struct Bf16ConvCase {
  int in_channels, out_channels, kernel, stride, padding, height, width;
};

class Bf16LayerTest : public KernelPathTest {};
RL_INSTANTIATE_KERNEL_PATHS(Bf16LayerTest);

// The outputs and gradients of a bf16 layer against the same layer in fp32 with the inputs of its
// products rounded (x, weight, output gradient): within twice the sharp bound (both sides round
// their fp32 sums), and against the fp32 layer on the unrounded inputs within the bf16 bound.
// `abs_layer` is an fp32 copy that gets |weight|, |x| and |dy|: its results are the bound scales.
template <class MakeLayer>
void CheckBf16Layer(const MakeLayer& make, int batch, int k, const std::string& what) {
  std::mt19937 rng(11);
  auto bf16 = make(&rng);
  auto fp32 = bf16;
  auto rounded = bf16;
  auto abs_layer = bf16;
  bf16.set_precision(Precision::kBf16);
  rounded.weight() = RoundedToBf16(bf16.weight());
  abs_layer.weight() = bf16.weight().cwiseAbs();
  abs_layer.bias().setZero();
  const Matrix x = RandomMatrix(bf16.input_size(), batch, &rng);
  const Matrix dy = RandomMatrix(bf16.output_size(), batch, &rng);
  const Matrix x_rounded = RoundedToBf16(x);
  const Matrix dy_rounded = RoundedToBf16(dy);
  const Matrix x_abs = x.cwiseAbs();
  const Matrix dy_abs = dy.cwiseAbs();
  const Matrix y = bf16.Forward(x);
  const Matrix y_fp32 = fp32.Forward(x);
  const Matrix y_rounded = rounded.Forward(x_rounded);
  const Matrix y_scale = abs_layer.Forward(x_abs) + bf16.bias().cwiseAbs() * Matrix::Ones(1, batch);
  const Matrix dx = bf16.Backward(dy);
  const Matrix dx_fp32 = fp32.Backward(dy);
  const Matrix dx_rounded = rounded.Backward(dy_rounded);
  const Matrix dx_scale = abs_layer.Backward(dy_abs);
  struct Check {
    const char* name;
    const Matrix& got;
    const Matrix& rounded;
    const Matrix& fp32;
    const Matrix& scale;
  };
  for (const Check& c : {Check{"output", y, y_rounded, y_fp32, y_scale},
                         Check{"input gradient", dx, dx_rounded, dx_fp32, dx_scale},
                         Check{"weight gradient", bf16.weight_grad(), rounded.weight_grad(),
                               fp32.weight_grad(), abs_layer.weight_grad()}}) {
    EXPECT_LE(WorstBoundRatio(c.got, c.rounded, c.scale, 2 * SharpBf16Bound(k)), 1.0)
        << what << " " << c.name << " against fp32 on rounded inputs";
    EXPECT_LE(WorstBoundRatio(c.got, c.fp32, c.scale, Bf16Bound(k)), 1.0)
        << what << " " << c.name << " against fp32";
    EXPECT_GT((c.got - c.fp32).cwiseAbs().maxCoeff(), 0.0f)
        << what << " " << c.name << " was not computed in bf16";
  }
}

TEST_P(Bf16LayerTest, ConvolutionsMatchTheFp32KernelOnRoundedInputs) {
  for (const Bf16ConvCase& g :
       {Bf16ConvCase{4, 32, 8, 4, 0, 84, 84}, Bf16ConvCase{32, 64, 4, 2, 0, 20, 20},
        Bf16ConvCase{64, 64, 3, 1, 0, 9, 9}, Bf16ConvCase{3, 20, 3, 2, 1, 13, 11},
        Bf16ConvCase{16, 32, 4, 2, 0, 20, 20}, Bf16ConvCase{8, 24, 5, 1, 0, 5, 5}}) {
    const int batch = 5;
    const int oh = (g.height + 2 * g.padding - g.kernel) / g.stride + 1;
    const int ow = (g.width + 2 * g.padding - g.kernel) / g.stride + 1;
    // The longest sum: the weight gradient's, over every output pixel of the batch.
    const int k = std::max({g.in_channels * g.kernel * g.kernel, batch * oh * ow,
                            g.out_channels * g.kernel * g.kernel});
    CheckBf16Layer(
        [&g](std::mt19937* rng) {
          return Conv2d(g.in_channels, g.out_channels, g.kernel, g.stride, g.padding, g.height,
                        g.width, rng);
        },
        batch, k,
        "conv2d(" + std::to_string(g.in_channels) + "," + std::to_string(g.out_channels) + "," +
            std::to_string(g.kernel) + "," + std::to_string(g.stride) + ")");
  }
}

TEST_P(Bf16LayerTest, LinearMatchesTheFp32KernelOnRoundedInputs) {
  for (const auto& [in, out, batch] :
       {std::array<int, 3>{256, 256, 256}, std::array<int, 3>{32, 256, 64},
        std::array<int, 3>{512, 128, 128}, std::array<int, 3>{84, 120, 32}}) {
    CheckBf16Layer([in = in, out = out](std::mt19937* rng) { return Linear(in, out, rng); }, batch,
                   std::max({in, out, batch}),
                   "linear(" + std::to_string(in) + "," + std::to_string(out) + ")");
  }
}

// Linear keeps its weight rounded into bf16 pairs from one change of the weight to the next
// (Param::version). Its forward pass is Gemm()'s in bf16 bit for bit, and after each writer of
// the weights it is that of a copy made then (which rounds the weights anew), bit for bit: a
// writer that did not mark the weights changed would leave the old pairs in use.
TEST_P(Bf16LayerTest, LinearRoundsItsWeightAnewAfterEveryWriter) {
  if (!NativeBf16()) GTEST_SKIP() << "the weight is kept in bf16 pairs on paths with AVX512_BF16";
  std::mt19937 rng(9);
  const Matrix x = RandomMatrix(300, 32, &rng);
  {
    Linear layer(300, 100, &rng);
    layer.set_precision(Precision::kBf16);
    Matrix want(100, 32);
    internal::Epilogue epilogue;
    epilogue.row_bias = layer.bias().data();
    internal::GemmWorkspace workspace;
    internal::Gemm(internal::View(std::as_const(layer).weight()), internal::View(x),
                   internal::View(&want), false, epilogue, &workspace, Precision::kBf16);
    EXPECT_EQ((layer.Forward(x) - want).cwiseAbs().maxCoeff(), 0.0f);
    EXPECT_EQ((layer.Forward(x) - want).cwiseAbs().maxCoeff(), 0.0f) << "the second pass";
  }
  const std::string architecture = "linear(300,100),relu,linear(100,64),relu,dueling(64,32,5)";
  Sequential net = BuildFromArchitecture(architecture, &rng);
  const Sequential other = BuildFromArchitecture(architecture, &rng);
  net.set_precision(Precision::kBf16);
  const auto gradients = [&net, &x, &rng] {
    net.ZeroGrad();
    net.Forward(x);
    net.BackwardParams(RandomMatrix(5, 32, &rng));
  };
  const auto check_after = [&net, &x](const char* writer, const auto& write) {
    const Matrix before = net.Forward(x);
    write();
    const Matrix after = net.Forward(x);
    Sequential copy = net;
    EXPECT_GT((after - before).cwiseAbs().maxCoeff(), 0.0f) << writer << " changed nothing";
    EXPECT_EQ((after - copy.Forward(x)).cwiseAbs().maxCoeff(), 0.0f)
        << "after " << writer << " the network computes with weights it no longer has";
  };
  Adam adam(net.Params(), 1e-2f);
  RmsProp rms_prop(net.Params(), 1e-2f);
  check_after("an Adam step", [&] {
    gradients();
    adam.Step();
  });
  check_after("an RMSprop step", [&] {
    gradients();
    rms_prop.Step();
  });
  check_after("SoftUpdateFrom", [&] { net.SoftUpdateFrom(other, 0.5f); });
  check_after("CopyParamsFrom", [&] { net.CopyParamsFrom(other); });
  std::vector<float> flat;
  other.GetFlat(&flat);
  for (float& v : flat) v *= 0.5f;
  check_after("SetFlat (a checkpoint's load)", [&] { net.SetFlat(flat.data(), flat.size()); });
  check_after("Linear::weight()", [&] {
    dynamic_cast<Linear&>(net.layer(0)).weight() *= 2.0f;  // NOLINT(cppcoreguidelines-pro-type-*)
  });
}

// A network passes its precision to every layer, new ones included, and copies keep it: the
// copy computes the same bits, and those differ from fp32's by no more than bf16 implies.
TEST_P(Bf16LayerTest, NetworksPassThePrecisionToTheirLayersAndCopiesKeepIt) {
  std::mt19937 rng(4);
  Sequential net = BuildFromArchitecture(
      "conv2d(2,16,3,1,1,10,10),relu,flatten,linear(1600,64),relu,dueling(64,32,5)", &rng);
  Sequential fp32 = net;
  net.set_precision(Precision::kBf16);
  EXPECT_EQ(net.precision(), Precision::kBf16);
  Sequential copy = net;
  Sequential assigned;
  assigned = net;
  EXPECT_EQ(copy.precision(), Precision::kBf16);
  const Matrix x = RandomMatrix(net.InputSize(), 24, &rng);
  const Matrix y = net.Forward(x);
  EXPECT_EQ((copy.Forward(x) - y).cwiseAbs().maxCoeff(), 0.0f);
  EXPECT_EQ((assigned.Forward(x) - y).cwiseAbs().maxCoeff(), 0.0f);
  const Matrix y_fp32 = fp32.Forward(x);
  const float diff = (y - y_fp32).cwiseAbs().maxCoeff();
  EXPECT_GT(diff, 0.0f);
  EXPECT_LT(diff, 0.05f * y_fp32.cwiseAbs().maxCoeff());
  net.set_precision(Precision::kFp32);
  EXPECT_EQ((net.Forward(x) - y_fp32).cwiseAbs().maxCoeff(), 0.0f);
}

}  // namespace
}  // namespace rl::nn
