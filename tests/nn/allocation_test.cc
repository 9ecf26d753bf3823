// The learner's update and the actors' single-observation inference must not touch the heap once
// shapes are stable.
#include <cstdint>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "nn/gemm.h"
#include "nn/losses.h"
#include "nn/optimizers.h"
#include "nn/parallel.h"
#include "nn/pixels.h"
#include "nn/precision.h"
#include "nn/presets.h"
#include "nn/sequential.h"
#include "tests/nn/allocation_counter.h"
#include "tests/nn/gradient_check.h"

namespace rl::nn {
namespace {

using testing::AllocationCount;
using testing::AllocationCountingAvailable;

// The heap allocations of `repeats` calls of `work` made after `warmup` calls (which may allocate:
// they size the buffers).
template <typename Work>
int64_t AllocationsOfRepeats(int warmup, int repeats, Work&& work) {
  for (int i = 0; i < warmup; ++i) work();
  const int64_t before = AllocationCount();
  for (int i = 0; i < repeats; ++i) work();
  return AllocationCount() - before;
}

// A batch for an update of a network: random non-negative inputs (as pixels are) and random
// gradients of its outputs.
struct Batch {
  Matrix x;
  Matrix dq;
};

Batch RandomBatch(const Sequential& net, int batch, std::mt19937* rng) {
  return {RandomMatrix(net.InputSize(), batch, rng).cwiseAbs(),
          RandomMatrix(net.OutputSize(), batch, rng)};
}

// The forward pass and the parameter gradients of one update.
void ForwardBackwardParams(Sequential* net, const Batch& batch) {
  net->Forward(batch.x);
  net->BackwardParams(batch.dq);
}

TEST(AllocationTest, CounterSeesAllocations) {
  ASSERT_TRUE(AllocationCountingAvailable()) << "this test needs glibc without a sanitizer";
  const int64_t before = AllocationCount();
  auto* v = new std::vector<float>(100);
  Matrix m(50, 50);
  delete v;
  EXPECT_GE(AllocationCount() - before, 3);
}

TEST(AllocationTest, PredictAndArgmaxDoNotAllocateAfterTheFirstCall) {
  ASSERT_TRUE(AllocationCountingAvailable()) << "this test needs glibc without a sanitizer";
  std::mt19937 rng(0);
  Sequential net = MakeMlp(4, {120, 84}, 2, &rng);
  const float obs[4] = {0.1f, -0.2f, 0.03f, 0.5f};
  net.Predict(obs, 4);
  const int64_t before = AllocationCount();
  int sum = 0;
  for (int i = 0; i < 100; ++i) {
    sum += net.Argmax(obs, 4);
    sum += static_cast<int>(net.Predict(obs, 4)(0, 0) > 0.0f);
  }
  EXPECT_EQ(AllocationCount() - before, 0) << sum;
}

TEST(AllocationTest, DqnUpdateDoesNotAllocateOnceShapesAreStable) {
  ASSERT_TRUE(AllocationCountingAvailable()) << "this test needs glibc without a sanitizer";
  std::mt19937 rng(0);
  constexpr int kBatch = 128;
  Sequential online = MakeMlp(4, {120, 84}, 2, &rng);
  Sequential target = online;
  const std::vector<Param> params = online.Params();
  Adam adam(params, 1e-3f);
  const Matrix obs = RandomMatrix(4, kBatch, &rng);
  const Matrix next_obs = RandomMatrix(4, kBatch, &rng);
  Vector q_taken(kBatch);
  Vector td_target(kBatch);
  Vector grad;
  Matrix grad_q(2, kBatch);
  auto update = [&] {
    const Matrix& q_next = target.Forward(next_obs);
    for (int j = 0; j < kBatch; ++j) td_target[j] = 1.0f + 0.99f * q_next.col(j).maxCoeff();
    const Matrix& q = online.Forward(obs);
    for (int j = 0; j < kBatch; ++j) q_taken[j] = q(j % 2, j);
    HuberLoss(q_taken, td_target, &grad);
    grad_q.setZero();
    for (int j = 0; j < kBatch; ++j) grad_q(j % 2, j) = grad[j];
    online.ZeroGrad();
    online.BackwardParams(grad_q);
    ClipGradNorm(params, 10.0f);
    adam.Step();
    target.SoftUpdateFrom(online, 0.005f);
  };
  EXPECT_EQ(AllocationsOfRepeats(1, 10, update), 0);
  // The full backward pass too.
  online.Forward(obs);
  online.Backward(grad_q);
  const int64_t after_warmup = AllocationCount();
  online.Forward(obs);
  online.Backward(grad_q);
  EXPECT_EQ(AllocationCount() - after_warmup, 0);
}

TEST(AllocationTest, NatureCnnPredictDoesNotAllocateAfterTheFirstCall) {
  ASSERT_TRUE(AllocationCountingAvailable()) << "this test needs glibc without a sanitizer";
  std::mt19937 rng(0);
  Sequential net = MakeNatureCnn(7, &rng);
  std::vector<float> obs(static_cast<size_t>(net.InputSize()));
  for (size_t i = 0; i < obs.size(); ++i) obs[i] = static_cast<float>(i % 256) / 255.0f;
  const int size = net.InputSize();
  net.Predict(obs.data(), size);
  const int64_t before = AllocationCount();
  int sum = 0;
  sum += net.Argmax(obs.data(), size);
  sum += static_cast<int>(net.Predict(obs.data(), size)(0, 0) > 0.0f);
  EXPECT_EQ(AllocationCount() - before, 0) << sum;
}

// The learner's update of a pixel network: uint8 conversion, both forward passes, backward
// through convolutions and batch normalisation, centred RMSProp.
TEST(AllocationTest, GraspCnnUpdateDoesNotAllocateOnceShapesAreStable) {
  ASSERT_TRUE(AllocationCountingAvailable()) << "this test needs glibc without a sanitizer";
  std::mt19937 rng(0);
  constexpr int kBatch = 8;
  constexpr int kActions = 3;
  Sequential online = MakeGraspCnn(kActions, &rng);
  Sequential target = online;
  target.set_training(false);
  const std::vector<Param> params = online.Params();
  RmsProp rmsprop(params, 2.5e-4f, 0.95f, 0.01f, /*centered=*/true);
  std::vector<uint8_t> pixels(static_cast<size_t>(online.InputSize()) * kBatch);
  for (size_t i = 0; i < pixels.size(); ++i) pixels[i] = static_cast<uint8_t>(i * 31 % 256);
  Matrix obs;
  Vector q_taken(kBatch);
  Vector td_target(kBatch);
  Vector grad;
  Matrix grad_q(kActions, kBatch);
  auto update = [&] {
    PixelsToMatrix(pixels.data(), online.InputSize(), kBatch, &obs);
    const Matrix& q_next = target.Forward(obs);
    for (int j = 0; j < kBatch; ++j) td_target[j] = 1.0f + 0.99f * q_next.col(j).maxCoeff();
    const Matrix& q = online.Forward(obs);
    for (int j = 0; j < kBatch; ++j) q_taken[j] = q(j % kActions, j);
    HuberLoss(q_taken, td_target, &grad);
    grad_q.setZero();
    for (int j = 0; j < kBatch; ++j) grad_q(j % kActions, j) = grad[j];
    online.ZeroGrad();
    online.BackwardParams(grad_q);
    ClipGradNorm(params, 10.0f);
    rmsprop.Step();
    target.CopyParamsFrom(online);
  };
  EXPECT_EQ(AllocationsOfRepeats(1, 3, update), 0);
}

// With two threads (nn/parallel.h) the pool hands out work without allocating and every task
// keeps its scratch space: convolutions split by samples, products by rows.
TEST(AllocationTest, PixelNetworksDoNotAllocateWithTwoThreads) {
  ASSERT_TRUE(AllocationCountingAvailable()) << "this test needs glibc without a sanitizer";
  SetNumThreads(2);
  std::mt19937 rng(0);
  Sequential nature = MakeNatureCnn(7, &rng);
  Sequential grasp = MakeGraspCnn(7, &rng);
  // Networks for single observations apart: a network that changes batch size reallocates.
  Sequential nature_actor = nature;
  Sequential grasp_actor = grasp;
  const int64_t sections = internal::ParallelSections();
  const Batch nature_batch = RandomBatch(nature, 4, &rng);
  const Batch grasp_batch = RandomBatch(grasp, 32, &rng);
  int sum = 0;
  const int64_t allocations = AllocationsOfRepeats(1, 3, [&] {
    ForwardBackwardParams(&nature, nature_batch);
    ForwardBackwardParams(&grasp, grasp_batch);
    sum += nature_actor.Argmax(nature_batch.x.data(), nature.InputSize()) +
           grasp_actor.Argmax(grasp_batch.x.data(), grasp.InputSize());
  });
  SetNumThreads(1);
  EXPECT_EQ(allocations, 0) << sum;
  EXPECT_GT(internal::ParallelSections(), sections) << "nothing ran on two threads";
}

// bf16 networks on every path this CPU runs (the AVX512_BF16 kernels, the emulation): an update
// of the Nature network and of an MLP, and a single observation, at 1 and 2 threads.
TEST(AllocationTest, Bf16NetworksDoNotAllocateOnEveryPath) {
  ASSERT_TRUE(AllocationCountingAvailable()) << "this test needs glibc without a sanitizer";
  for (const std::string& path : RunnableKernelPaths()) {
    SetKernelPath(path);
    for (int threads : {1, 2}) {
      SetNumThreads(threads);
      std::mt19937 rng(0);
      Sequential nature = MakeNatureCnn(7, &rng);
      Sequential mlp = MakeMlp(10, {256, 256}, 1, &rng);
      nature.set_precision(Precision::kBf16);
      mlp.set_precision(Precision::kBf16);
      Sequential actor = nature;
      const Batch nature_batch = RandomBatch(nature, 4, &rng);
      const Batch mlp_batch = RandomBatch(mlp, 256, &rng);
      int sum = 0;
      const int64_t allocations = AllocationsOfRepeats(2, 3, [&] {
        ForwardBackwardParams(&nature, nature_batch);
        mlp.Forward(mlp_batch.x);
        mlp.Backward(mlp_batch.dq);
        sum += actor.Argmax(nature_batch.x.data(), nature.InputSize());
      });
      EXPECT_EQ(allocations, 0) << path << ", " << threads << " threads " << sum;
    }
  }
  SetNumThreads(1);
  SetKernelPath("auto");
}

// Emulated bf16 products (a path without bf16 instructions) keep their operands' rounded copies
// in the workspace, not in buffers of the running thread: with a warm workspace, a thread that
// never ran a product allocates nothing. (Which of the pool's threads runs a task varies, so a
// worker may first run one after the warm-up; with per-thread buffers it allocated then.)
TEST(AllocationTest, EmulatedBf16ProductsAllocateNothingOnAThreadNewToThem) {
  ASSERT_TRUE(AllocationCountingAvailable()) << "this test needs glibc without a sanitizer";
  SetKernelPath("avx2");
  SetNumThreads(1);
  std::mt19937 rng(0);
  const Matrix a = RandomMatrix(64, 96, &rng);
  const Matrix b = RandomMatrix(96, 48, &rng);
  Matrix c(64, 48);
  internal::GemmWorkspace workspace;
  const auto product = [&] {
    internal::Gemm(internal::View(a), internal::View(b), internal::View(&c), /*accumulate=*/false,
                   {}, &workspace, Precision::kBf16);
  };
  product();  // the warm-up sizes the workspace
  int64_t allocations = -1;
  std::thread other([&] {
    const int64_t before = AllocationCount();
    product();
    allocations = AllocationCount() - before;
  });
  other.join();
  EXPECT_EQ(allocations, 0);
  SetKernelPath("auto");
}

}  // namespace
}  // namespace rl::nn
