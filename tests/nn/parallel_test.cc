// Intra-op threads (nn/parallel.h): the pool itself, and that products, convolutions, pooling,
// the pixel conversions and whole networks give the single-threaded results with 2 and 3 threads:
// bit for bit, except the parameter gradients of convolutions (summed per thread), which must agree
// to rounding.
#include "nn/parallel.h"

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <memory>
#include <random>
#include <stdexcept>
#include <thread>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "nn/activations.h"
#include "nn/conv2d.h"
#include "nn/gemm.h"
#include "nn/gemv.h"
#include "nn/pixels.h"
#include "nn/pool2d.h"
#include "nn/presets.h"
#include "nn/sequential.h"
#include "tests/nn/gradient_check.h"
#include "tests/nn/kernel_paths.h"

namespace rl::nn {
namespace {

// Sets the thread count for one scope and restores 1 (the default) after it.
class Threads {
 public:
  explicit Threads(int n) { SetNumThreads(n); }
  ~Threads() { SetNumThreads(1); }
  Threads(const Threads&) = delete;
  Threads& operator=(const Threads&) = delete;
};

// Largest absolute difference; 0 means bit-identical for finite values of equal shape.
float MaxDiff(const Matrix& a, const Matrix& b) {
  EXPECT_EQ(a.rows(), b.rows());
  EXPECT_EQ(a.cols(), b.cols());
  if (a.rows() != b.rows() || a.cols() != b.cols()) return 1e30f;
  return a.size() == 0 ? 0.0f : (a - b).cwiseAbs().maxCoeff();
}

// Rounding tolerance for sums that were split between threads, relative to `scale` (the largest
// entry of a gradient, or of all the gradients of a network: a gradient that should be 0, such
// as the bias of a convolution before batch normalisation, is rounding noise of that size).
void ExpectClose(const Matrix& got, const Matrix& want, float scale, const char* what) {
  EXPECT_LE(MaxDiff(got, want), 1e-5f * scale) << what;
}
float MaxAbs(const Matrix& m) { return m.size() == 0 ? 0.0f : m.cwiseAbs().maxCoeff(); }

TEST(ParallelTest, SetNumThreadsValidatesAndReports) {
  EXPECT_EQ(NumThreads(), 1);
  EXPECT_THROW(SetNumThreads(0), std::invalid_argument);
  EXPECT_THROW(SetNumThreads(65), std::invalid_argument);
  EXPECT_EQ(NumThreads(), 1);
  {
    Threads threads(3);
    EXPECT_EQ(NumThreads(), 3);
    SetNumThreads(2);
    EXPECT_EQ(NumThreads(), 2);
  }
  EXPECT_EQ(NumThreads(), 1);
}

TEST(ParallelTest, TasksForSplitsOnlyLargeWorkAndNeverNests) {
  constexpr int64_t kLarge = 100 * internal::kMinTaskWork;
  EXPECT_EQ(internal::TasksFor(kLarge, 8), 1);  // One thread.
  Threads threads(3);
  EXPECT_EQ(internal::TasksFor(kLarge, 8), 3);
  EXPECT_EQ(internal::TasksFor(kLarge, 2), 2);  // At most max_pieces.
  EXPECT_EQ(internal::TasksFor(2 * internal::kMinTaskWork, 8), 2);
  EXPECT_EQ(internal::TasksFor(internal::kMinTaskWork - 1, 8), 1);
  std::vector<int> nested(3, 0);
  internal::ParallelFor(3, [&](int task) { nested[task] = internal::TasksFor(kLarge, 8); });
  EXPECT_EQ(nested, std::vector<int>({1, 1, 1}));
}

TEST(ParallelTest, ParallelSectionsCountsCallsRunByThePool) {
  const int64_t start = internal::ParallelSections();
  internal::ParallelFor(2, [](int) {});  // One thread: no pool.
  EXPECT_EQ(internal::ParallelSections(), start);
  Threads threads(2);
  internal::ParallelFor(1, [](int) {});
  EXPECT_EQ(internal::ParallelSections(), start);
  internal::ParallelFor(2, [](int) { internal::ParallelFor(2, [](int) {}); });  // Nested: serial.
  EXPECT_EQ(internal::ParallelSections(), start + 1);
}

TEST(ParallelTest, ParallelForRunsEveryTaskOnce) {
  for (int n : {1, 2, 3}) {
    Threads threads(n);
    for (int tasks : {1, 2, 3, 5}) {  // Also more tasks than threads.
      for (int call = 0; call < 50; ++call) {
        std::vector<int> runs(static_cast<size_t>(tasks), 0);
        internal::ParallelFor(tasks, [&](int task) { ++runs[static_cast<size_t>(task)]; });
        ASSERT_EQ(runs, std::vector<int>(static_cast<size_t>(tasks), 1))
            << n << " threads, " << tasks << " tasks";
      }
    }
  }
}

TEST(ParallelTest, CallersOnSeveralThreadsShareThePool) {
  // Whoever finds the pool busy runs its tasks itself; every call still runs each task once.
  Threads threads(2);
  std::atomic<int> bad{0};
  auto caller = [&] {
    for (int call = 0; call < 200; ++call) {
      std::vector<int> runs(4, 0);
      internal::ParallelFor(4, [&](int task) { ++runs[static_cast<size_t>(task)]; });
      if (runs != std::vector<int>(4, 1)) ++bad;
    }
  };
  std::thread a(caller);
  std::thread b(caller);
  caller();
  a.join();
  b.join();
  EXPECT_EQ(bad.load(), 0);
}

// Gemm at 1 thread, then at 2 and 3: same bits, in both precisions.
void CheckGemm(const internal::ConstView& a, const internal::ConstView& b, int m, int n,
               bool accumulate, const internal::Epilogue& epilogue, const Matrix& start) {
  ASSERT_GE(static_cast<int64_t>(m) * n * a.cols, 2 * internal::kMinTaskWork)
      << "too small to split";
  internal::GemmWorkspace workspace;
  for (Precision precision : {Precision::kFp32, Precision::kBf16}) {
    Matrix want = start;
    internal::Gemm(a, b, internal::View(&want), accumulate, epilogue, &workspace, precision);
    for (int n_threads : {2, 3}) {
      Threads threads(n_threads);
      Matrix got = start;
      internal::Gemm(a, b, internal::View(&got), accumulate, epilogue, &workspace, precision);
      EXPECT_EQ(MaxDiff(got, want), 0.0f) << m << "x" << n << "x" << a.cols << ", " << n_threads
                                          << " threads, " << PrecisionName(precision);
    }
  }
}

TEST(ParallelTest, TasksForElementsSplitsOnlyLongPasses) {
  EXPECT_EQ(internal::TasksForElements(100 * internal::kMinTaskElements, 8), 1);  // One thread.
  Threads threads(3);
  EXPECT_EQ(internal::TasksForElements(100 * internal::kMinTaskElements, 8), 3);
  EXPECT_EQ(internal::TasksForElements(2 * internal::kMinTaskElements, 8), 2);
  EXPECT_EQ(internal::TasksForElements(internal::kMinTaskElements - 1, 8), 1);
}

// Its ranges follow each other and cover the whole batch, cut as TasksForElements says.
TEST(ParallelTest, ParallelForColumnsCoversTheBatchInConsecutiveRanges) {
  Threads threads(3);
  for (const int64_t batch : {1, 2, 7, 64}) {
    for (const int64_t elements :
         {int64_t{1}, 2 * internal::kMinTaskElements, 100 * internal::kMinTaskElements}) {
      std::vector<std::pair<int64_t, int64_t>> ranges(8, {-1, -1});
      std::atomic<int> calls{0};
      internal::ParallelForColumns(batch, elements, [&](int64_t begin, int64_t end) {
        ranges[static_cast<size_t>(calls.fetch_add(1))] = {begin, end};
      });
      const int tasks = internal::TasksForElements(elements, batch);
      ASSERT_EQ(calls.load(), tasks) << "batch " << batch << ", elements " << elements;
      ranges.resize(static_cast<size_t>(tasks));
      std::sort(ranges.begin(), ranges.end());
      int64_t next = 0;
      for (const auto& [begin, end] : ranges) {
        EXPECT_EQ(begin, next);
        EXPECT_GT(end, begin);
        next = end;
      }
      EXPECT_EQ(next, batch);
    }
  }
}

// The pixel conversions, ReLU and both pooling layers, forward and backward, at about the
// car_racing_td3 learner's sizes (batch 64 of 4 x 84 x 84 stacks; 32 channels of 41 x 41, twice
// the car encoder's first pooling): the same bits with 2 and 3 threads as with one, and the pool
// did run them.
TEST(ParallelTest, PixelsReluAndPoolingGiveTheSameBitsWithThreads) {
  constexpr int kBatch = 64, kPlanes = 4, kSide = 84;
  std::mt19937 rng(5);
  std::vector<uint8_t> pixels(static_cast<size_t>(kPlanes) * kSide * kSide * kBatch);
  for (uint8_t& p : pixels) p = static_cast<uint8_t>(rng());
  std::vector<int> dy(kBatch), dx(kBatch);
  for (int j = 0; j < kBatch; ++j) {
    dy[static_cast<size_t>(j)] = static_cast<int>(rng() % 9) - 4;
    dx[static_cast<size_t>(j)] = static_cast<int>(rng() % 9) - 4;
  }
  const int features = kPlanes * kSide * kSide;
  const Matrix x = RandomMatrix(32 * 41 * 41, kBatch, &rng);
  // Many ties (values rounded to quarters) for the max mode's first-of-equal-maxima rule.
  const Matrix tied = (x * 4.0f).array().round().matrix();
  const Matrix dy_pool = RandomMatrix(32 * 20 * 20, kBatch, &rng);
  struct Result {
    Matrix plain, shifted;
    std::vector<Matrix> pooled;
  };
  const auto run = [&] {
    Result r;
    PixelsToMatrix(pixels.data(), features, kBatch, &r.plain);
    ShiftedPixelsToMatrix(pixels.data(), kPlanes, kSide, kSide, kBatch, dy.data(), dx.data(),
                          &r.shifted);
    ReLU relu;
    r.pooled.push_back(relu.Forward(x));
    r.pooled.push_back(relu.Backward(tied));
    for (const Pool2d::Mode mode : {Pool2d::Mode::kMax, Pool2d::Mode::kAverage}) {
      for (const Matrix* in : {&x, &tied}) {
        Pool2d pool(mode, 32, 2, 41, 41);
        r.pooled.push_back(pool.Forward(*in));
        r.pooled.push_back(pool.Backward(dy_pool));
      }
    }
    return r;
  };
  const Result want = run();
  for (int n_threads : {2, 3}) {
    Threads threads(n_threads);
    const int64_t sections = internal::ParallelSections();
    const Result got = run();
    EXPECT_EQ(internal::ParallelSections() - sections, 2 + 2 + 2 * 2 * 2)
        << n_threads << " threads";
    EXPECT_EQ(MaxDiff(got.plain, want.plain), 0.0f) << n_threads << " threads";
    EXPECT_EQ(MaxDiff(got.shifted, want.shifted), 0.0f) << n_threads << " threads";
    ASSERT_EQ(got.pooled.size(), want.pooled.size());
    for (size_t i = 0; i < got.pooled.size(); ++i) {
      EXPECT_EQ(MaxDiff(got.pooled[i], want.pooled[i]), 0.0f) << i << ", " << n_threads;
    }
  }
}

// The computations run on every kernel path this CPU can run.
class ParallelKernelTest : public KernelPathTest {};
RL_INSTANTIATE_KERNEL_PATHS(ParallelKernelTest);

TEST_P(ParallelKernelTest, GemmGivesTheSameBitsWithThreads) {
  std::mt19937 rng(1);
  {
    // A large column-major weight times a batch (packed a block at a time), bias and ReLU;
    // split by rows.
    const Matrix w = RandomMatrix(264, 1100, &rng);
    const Matrix x = RandomMatrix(1100, 32, &rng);
    const Matrix bias = RandomMatrix(264, 1, &rng);
    internal::Epilogue e;
    e.row_bias = bias.data();
    e.relu = true;
    CheckGemm(internal::View(w), internal::View(x), 264, 32, false, e, Matrix::Zero(264, 32));
  }
  {
    // A transposed weight times a gradient with a ReLU mask (an input gradient), ragged rows.
    const Matrix w = RandomMatrix(300, 1031, &rng);
    const Matrix g = RandomMatrix(300, 40, &rng);
    const Matrix mask = RandomMatrix(1031, 40, &rng);
    internal::Epilogue e;
    e.mask = mask.data();
    CheckGemm(internal::View(w).Transposed(), internal::View(g), 1031, 40, false, e,
              Matrix::Zero(1031, 40));
  }
  {
    // A weight gradient: accumulate dY x^T into a start value, column bias.
    const Matrix dy = RandomMatrix(127, 200, &rng);
    const Matrix x = RandomMatrix(400, 200, &rng);
    const Matrix col_bias = RandomMatrix(400, 1, &rng);
    internal::Epilogue e;
    e.col_bias = col_bias.data();
    CheckGemm(internal::View(dy), internal::View(x).Transposed(), 127, 400, true, e,
              RandomMatrix(127, 400, &rng));
  }
  {
    // One full panel of rows only: split by columns.
    const Matrix a = RandomMatrix(30, 800, &rng);
    const Matrix b = RandomMatrix(800, 403, &rng);
    CheckGemm(internal::View(a), internal::View(b), 30, 403, false, {}, Matrix::Zero(30, 403));
  }
}

TEST_P(ParallelKernelTest, GemmPackedGivesTheSameBitsWithThreads) {
  std::mt19937 rng(2);
  for (Precision precision : {Precision::kFp32, Precision::kBf16}) {
    const int rows = internal::PackedPanelRows(precision);
    for (int m : {400, 30}) {  // Split by rows, then by columns.
      const int k = 256;
      const int n = m == 400 ? 96 : 1200;
      ASSERT_GE(static_cast<int64_t>(m) * n * k, 2 * internal::kMinTaskWork)
          << "too small to split";
      const Matrix a = RandomMatrix(m, k, &rng);
      const Matrix b = RandomMatrix(k, n, &rng);
      const Matrix col_bias = RandomMatrix(n, 1, &rng);
      const int panels = (m + rows - 1) / rows;
      std::vector<float> packed(static_cast<size_t>(panels) * rows * k, 0.0f);
      for (int i = 0; i < m; ++i) {
        for (int p = 0; p < k; ++p) {
          packed[static_cast<size_t>((i / rows) * rows * k + p * rows + i % rows)] = a(i, p);
        }
      }
      internal::Epilogue e;
      e.col_bias = col_bias.data();
      e.relu = true;
      internal::GemmWorkspace workspace;
      Matrix want(m, n);
      internal::GemmPacked(packed.data(), m, k, internal::View(b), internal::View(&want), false, e,
                           &workspace, precision);
      const Matrix exact = ((a * b).rowwise() + col_bias.col(0).transpose()).cwiseMax(0.0f);
      EXPECT_LE(MaxDiff(want, exact), precision == Precision::kFp32 ? 1e-4f : 0.1f);
      for (int n_threads : {2, 3}) {
        Threads threads(n_threads);
        Matrix got(m, n);
        internal::GemmPacked(packed.data(), m, k, internal::View(b), internal::View(&got), false, e,
                             &workspace, precision);
        EXPECT_EQ(MaxDiff(got, want), 0.0f)
            << m << " rows, " << n_threads << " threads, " << PrecisionName(precision);
      }
    }
  }
}

TEST_P(ParallelKernelTest, GemvGivesTheSameBitsWithThreads) {
  std::mt19937 rng(3);
  // Gemv counts a multiply-add as 4 of a matrix product's (it is bound by reading the weight).
  for (const auto& [out, in] : {std::pair{512, 4200}, std::pair{300, 7200}}) {
    ASSERT_GE(4 * static_cast<int64_t>(out) * in, 2 * internal::kMinTaskWork) << "too small";
    const Matrix w = RandomMatrix(out, in, &rng);
    const Matrix x = RandomMatrix(in, 1, &rng);
    const Matrix b = RandomMatrix(out, 1, &rng);
    Matrix want(out, 1);
    internal::Gemv(w.data(), out, in, x.data(), b.data(), /*relu=*/true, want.data());
    EXPECT_LE(MaxDiff(want, (w * x + b).cwiseMax(0.0f)), 1e-6f * static_cast<float>(in));
    for (int n_threads : {2, 3}) {
      Threads threads(n_threads);
      Matrix got(out, 1);
      internal::Gemv(w.data(), out, in, x.data(), b.data(), /*relu=*/true, got.data());
      EXPECT_EQ(MaxDiff(got, want), 0.0f) << out << "x" << in << ", " << n_threads << " threads";
    }
  }
}

struct ConvCase {
  int in_c, out_c, kernel, stride, padding, h, w, batch;
  bool relu_out, relu_grad_in;
};

// Forward() and Backward() of a fresh layer on x and dy at the current thread count.
struct ConvResult {
  Matrix y, dx, dw, db;
};
ConvResult RunConv(const ConvCase& c, const Matrix& x, const Matrix& dy) {
  std::mt19937 rng(7);
  Conv2d conv(c.in_c, c.out_c, c.kernel, c.stride, c.padding, c.h, c.w, &rng);
  if (c.relu_out) conv.FuseOutputRelu();
  if (c.relu_grad_in) conv.FuseInputReluGrad();
  ConvResult r;
  r.y = conv.Forward(x);
  r.dx = conv.Backward(dy);
  // A second pass accumulates into the parameter gradients, as Backward() promises.
  conv.Forward(x);
  conv.Backward(dy);
  r.dw = conv.weight_grad();
  r.db = conv.bias_grad();
  return r;
}

TEST_P(ParallelKernelTest, Conv2dGivesTheSameResultsWithThreads) {
  const ConvCase cases[] = {
      {4, 32, 8, 4, 0, 84, 84, 7, true, false},  // Nature layer 1, odd batch.
      {3, 16, 3, 2, 1, 33, 29, 80, true, true},  // Padding, non-square, many groups.
      {64, 64, 3, 1, 0, 9, 9, 6, false, true},   // Stride 1: the input read in place.
      {64, 64, 3, 1, 0, 3, 3, 256, true, true},  // The kernel covers the input: dense.
      {32, 64, 4, 2, 0, 40, 40, 1, true, true},  // A single sample: rows of the product split.
  };
  for (const ConvCase& c : cases) {
    std::mt19937 rng(static_cast<unsigned>(c.in_c * 131 + c.h));
    const int in_size = c.in_c * c.h * c.w;
    const int oh = (c.h + 2 * c.padding - c.kernel) / c.stride + 1;
    const int ow = (c.w + 2 * c.padding - c.kernel) / c.stride + 1;
    // Inputs after a ReLU where the layer masks its input gradient: about half zeros.
    Matrix x = RandomMatrix(in_size, c.batch, &rng);
    if (c.relu_grad_in) x = x.cwiseMax(0.0f);
    const Matrix dy = RandomMatrix(c.out_c * oh * ow, c.batch, &rng);
    const ConvResult want = RunConv(c, x, dy);
    const int64_t work =
        static_cast<int64_t>(c.batch) * oh * ow * c.in_c * c.kernel * c.kernel * c.out_c;
    for (int n_threads : {2, 3}) {
      Threads threads(n_threads);
      EXPECT_GE(work, 2 * internal::kMinTaskWork) << "this case would not be split";
      const ConvResult got = RunConv(c, x, dy);
      const ConvResult again = RunConv(c, x, dy);
      EXPECT_EQ(MaxDiff(got.y, want.y), 0.0f) << c.h << "x" << c.w << ", " << n_threads;
      EXPECT_EQ(MaxDiff(got.dx, want.dx), 0.0f) << c.h << "x" << c.w << ", " << n_threads;
      ExpectClose(got.dw, want.dw, MaxAbs(want.dw), "weight gradient");
      ExpectClose(got.db, want.db, MaxAbs(want.db), "bias gradient");
      // Deterministic for a given thread count.
      EXPECT_EQ(MaxDiff(again.dw, got.dw), 0.0f);
      EXPECT_EQ(MaxDiff(again.db, got.db), 0.0f);
    }
  }
}

// Q values, input gradient and parameter gradients of a network for one batch.
struct NetResult {
  Matrix q, dx;
  std::vector<Matrix> grads;
  Matrix greedy;  // Predict() of the first observation.
};
NetResult RunNet(Sequential* net, const Matrix& x, const Matrix& dq) {
  NetResult r;
  net->ZeroGrad();
  r.q = net->Forward(x);
  r.dx = net->Backward(dq);
  for (const Param& p : net->Params()) r.grads.push_back(*p.grad);
  r.greedy = net->Predict(x.data(), static_cast<int>(x.rows()));
  return r;
}

TEST_P(ParallelKernelTest, NetworksGiveTheSameResultsWithThreads) {
  for (const int variant : {0, 1, 2}) {
    const bool nature = variant != 1;
    std::mt19937 rng(11);
    Sequential net = nature ? MakeNatureCnn(7, &rng) : MakeGraspCnn(7, &rng);
    if (variant == 2) net.set_precision(Precision::kBf16);
    const int batch = nature ? 4 : 32;  // Enough for the convolutions to be split.
    Matrix x = RandomMatrix(net.InputSize(), batch, &rng).cwiseAbs();
    const Matrix dq = RandomMatrix(7, batch, &rng);
    Sequential copy = net;
    const NetResult want = RunNet(&copy, x, dq);
    for (int n_threads : {2, 3}) {
      Threads threads(n_threads);
      Sequential threaded = net;
      const NetResult got = RunNet(&threaded, x, dq);
      EXPECT_EQ(MaxDiff(got.q, want.q), 0.0f) << (nature ? "nature" : "grasp");
      EXPECT_EQ(MaxDiff(got.dx, want.dx), 0.0f) << (nature ? "nature" : "grasp");
      EXPECT_EQ(MaxDiff(got.greedy, want.greedy), 0.0f) << (nature ? "nature" : "grasp");
      ASSERT_EQ(got.grads.size(), want.grads.size());
      float scale = 0.0f;
      for (const Matrix& g : want.grads) scale = std::max(scale, MaxAbs(g));
      for (size_t i = 0; i < got.grads.size(); ++i) {
        ExpectClose(got.grads[i], want.grads[i], scale, net.Params()[i].name.c_str());
      }
    }
  }
}

}  // namespace
}  // namespace rl::nn
