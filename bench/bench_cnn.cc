// Pixel networks at 1 and 2 threads (nn::SetNumThreads), in fp32 and bf16 (nn/precision.h),
// beside the PyTorch peer's micro.py modes `nature`, `small` and `latency`:
//
//   learner_updates_nature_cnn, learner_updates_grasp_cnn (updates/s): DQN updates of
//     MakeNatureCnn(7) on 4x84x84 and MakeGraspCnn(7) on 4x40x40 uint8 frames at batch 32, the
//     work micro.py's `nature` and `small` modes time (see kUpdateWork).
//   inference_latency_nature_cnn, inference_latency_grasp_cnn (ms): one uint8 observation to a
//     greedy action, median over calls, as micro.py's `latency` (which has the Nature CNN only);
//     inference_latency_td3_car_actor, inference_latency_td3_drq_actor: one observation to an
//     action through the TD3 CarRacing article's actor and through the drq policy (the shared
//     encoder and its actor head), what a car_racing_td3 actor computes per step.
//   conv_gflops_nature_cnn, conv_gflops_grasp_cnn (GFLOP/s): the convolution layers of the
//     network alone, at batch 32: "forward", "backward" (weight gradients, and input gradients
//     of all but the first layer, as in an update) and "update" (two forward passes and one
//     backward pass, the convolution work of one update). FLOPs are 2 x multiply-adds, counted
//     from the layer shapes, in either precision.
//   peak_fp32_gflops (GFLOP/s): the FMA throughput of the machine, measured with independent
//     chains of vector FMAs of the widest width the CPU has (per core at 1 thread; at 2 threads
//     the sum of two cores); "gflops_256bit" with 256-bit FMAs.
//   peak_bf16_gflops (GFLOP/s): the same with vdpbf16ps (AVX512_BF16: per 32-bit lane two bf16
//     products added to an fp32 sum, 4 FLOPs), 512-bit, and "gflops_256bit"; only on CPUs with
//     AVX512_BF16.
//
// Every line has "threads" (the SetNumThreads() setting) and "threads_used": the setting if the
// measured operation ran parallel sections ("parallel_sections_per_call"), else 1 (a
// single observation is too small to be split, so its latency is the 1-thread path); the network
// lines have "precision", "kernels" (the kernel path, nn/precision.h) and "bf16_native" (false:
// bf16 emulated on this CPU).
//
// Usage: bench_cnn [repeats (5)] [seconds per measurement (1.0)] [thread counts ("1,2")]
//                  [what ("nature_cnn,grasp_cnn,actors")]
#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <memory>
#include <random>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <immintrin.h>

#include "bench/bench_util.h"
#include "nn/activations.h"
#include "nn/conv2d.h"
#include "nn/kernels_target.h"
#include "nn/linear.h"
#include "nn/losses.h"
#include "nn/optimizers.h"
#include "nn/parallel.h"
#include "nn/pixels.h"
#include "nn/precision.h"
#include "nn/presets.h"
#include "nn/sequential.h"

namespace {

using rl::nn::Matrix;
using rl::nn::Sequential;
using rl::nn::Vector;
using Clock = std::chrono::steady_clock;

// What micro.py uses for both CNNs (make_update, NatureCNN/SmallCNN defaults).
constexpr int kBatch = 32;
constexpr int kActions = 7;
constexpr float kGamma = 0.99f;
constexpr float kLearningRate = 1e-4f;
constexpr int kBatches = 8;  // Pre-generated batches, cycled.
constexpr double kDoneProbability = 0.05;

const char* const kUpdateWork =
    "uint8 next_obs and obs to x/255, target forward on next_obs (eval mode, no gradients), max "
    "over actions, TD target r + 0.99 max (1 - done), online forward on obs (training mode), "
    "gather of the taken actions, Huber loss (smooth_l1, mean), zero grad, backward (parameter "
    "gradients only, no input gradient: the peer's input does not require grad), Adam step (lr "
    "1e-4); no gradient clipping, no target copy, 8 pre-generated batches cycled: micro.py's "
    "update()";

std::string Num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%.6g", v);
  return buf;
}

struct NetSpec {
  std::string name;      // Our bench-name suffix: nature_cnn, grasp_cnn.
  std::string peer_net;  // micro.py's name, or "" if the peer has no such measurement.
  std::function<Sequential(std::mt19937*)> make;
};

// FLOPs (2 x multiply-adds) of the matrix products of one DQN update at `batch`: forward passes
// of the target and the online network, then weight gradients of every layer and input
// gradients of every layer but the first (Sequential::BackwardParams()).
struct Flops {
  double conv_forward = 0;   // One forward pass, convolutions only.
  double conv_backward = 0;  // One backward pass, convolutions only.
  double other_forward = 0;  // Linear layers.
  double other_backward = 0;
  double ConvUpdate() const { return 2 * conv_forward + conv_backward; }
  double Update() const { return ConvUpdate() + 2 * other_forward + other_backward; }
};

Flops CountFlops(const Sequential& net, int batch) {
  Flops f;
  for (int i = 0; i < net.num_layers(); ++i) {
    const rl::nn::Layer& layer = net.layer(i);
    const int gradients = i == 0 ? 1 : 2;  // dW, plus dX after the first layer.
    if (const auto* conv = dynamic_cast<const rl::nn::Conv2d*>(&layer)) {
      const rl::nn::ImageShape in = conv->input_shape();
      const rl::nn::ImageShape out = conv->output_shape();
      const double taps = static_cast<double>(in.channels) * conv->kernel() * conv->kernel();
      const double pass = 2.0 * batch * out.height * out.width * out.channels * taps;
      f.conv_forward += pass;
      f.conv_backward += gradients * pass;
    } else if (dynamic_cast<const rl::nn::Linear*>(&layer) != nullptr) {
      const double pass = 2.0 * batch * layer.input_size() * layer.output_size();
      f.other_forward += pass;
      f.other_backward += gradients * pass;
    }
  }
  return f;
}

std::vector<uint8_t> RandomPixels(size_t n, std::mt19937* rng) {
  std::uniform_int_distribution<int> byte(0, 255);
  std::vector<uint8_t> v(n);
  for (uint8_t& b : v) b = static_cast<uint8_t>(byte(*rng));
  return v;
}

// One DQN update as micro.py's make_update(): see kUpdateWork.
class DqnUpdate {
 public:
  DqnUpdate(Sequential net, int batch, std::mt19937* rng)
      : online_(std::move(net)),
        target_(online_),
        adam_(online_.Params(), kLearningRate),
        batch_(batch),
        features_(online_.InputSize()) {
    target_.set_training(false);
    std::uniform_int_distribution<int> action(0, kActions - 1);
    std::bernoulli_distribution done(kDoneProbability);
    for (int i = 0; i < kBatches; ++i) {
      Batch d;
      d.obs = RandomPixels(static_cast<size_t>(features_) * batch, rng);
      d.next_obs = RandomPixels(static_cast<size_t>(features_) * batch, rng);
      for (int j = 0; j < batch; ++j) {
        d.action.push_back(action(*rng));
        d.reward.push_back(1.0f);
        d.done.push_back(done(*rng) ? 1.0f : 0.0f);
      }
      data_.push_back(std::move(d));
    }
    td_target_.resize(batch);
    q_taken_.resize(batch);
    grad_q_.resize(kActions, batch);
  }

  void Run() {
    const Batch& d = data_[next_++ % data_.size()];
    rl::nn::PixelsToMatrix(d.next_obs.data(), features_, batch_, &next_obs_);
    const Matrix& q_next = target_.Forward(next_obs_);
    for (int j = 0; j < batch_; ++j) {
      td_target_[j] = d.reward[j] + kGamma * q_next.col(j).maxCoeff() * (1.0f - d.done[j]);
    }
    rl::nn::PixelsToMatrix(d.obs.data(), features_, batch_, &obs_);
    const Matrix& q = online_.Forward(obs_);
    for (int j = 0; j < batch_; ++j) q_taken_[j] = q(d.action[j], j);
    rl::nn::HuberLoss(q_taken_, td_target_, &grad_);
    grad_q_.setZero();
    for (int j = 0; j < batch_; ++j) grad_q_(d.action[j], j) = grad_[j];
    online_.ZeroGrad();
    online_.BackwardParams(grad_q_);
    adam_.Step();
  }

 private:
  struct Batch {
    std::vector<uint8_t> obs, next_obs;
    std::vector<int> action;
    std::vector<float> reward, done;
  };
  Sequential online_;
  Sequential target_;
  rl::nn::Adam adam_;
  int batch_;
  int features_;
  std::vector<Batch> data_;
  size_t next_ = 0;
  Matrix obs_, next_obs_, grad_q_;
  Vector td_target_, q_taken_, grad_;
};

// The convolution layers of a network, rebuilt alone with the same shapes and the same fused
// ReLUs as inside it (a ReLU after a layer is applied by it; the backward pass of a ReLU before
// it too), fed random inputs of the right shapes.
class ConvStack {
 public:
  ConvStack(const Sequential& net, int batch, rl::nn::Precision precision, std::mt19937* rng) {
    std::normal_distribution<float> normal;
    std::uniform_real_distribution<float> unit;
    auto is_relu = [&net](int i) {
      return i >= 0 && i < net.num_layers() &&
             dynamic_cast<const rl::nn::ReLU*>(&net.layer(i)) != nullptr;
    };
    for (int i = 0; i < net.num_layers(); ++i) {
      const auto* conv = dynamic_cast<const rl::nn::Conv2d*>(&net.layer(i));
      if (conv == nullptr) continue;
      const rl::nn::ImageShape in = conv->input_shape();
      auto layer = std::make_unique<rl::nn::Conv2d>(in.channels, conv->output_shape().channels,
                                                    conv->kernel(), conv->stride(), conv->padding(),
                                                    in.height, in.width, rng);
      layer->set_precision(precision);
      if (is_relu(i + 1)) layer->FuseOutputRelu();
      if (is_relu(i - 1)) layer->FuseInputReluGrad();
      Matrix x(in.size(), batch);
      // Pixels / 255 for the first layer, ReLU outputs for the others.
      for (float& v : x.reshaped()) v = i == 0 ? unit(*rng) : std::max(normal(*rng), 0.0f);
      Matrix g(layer->output_size(), batch);
      for (float& v : g.reshaped()) v = 1e-3f * normal(*rng);
      first_.push_back(i == 0);
      layers_.push_back(std::move(layer));
      inputs_.push_back(std::move(x));
      grads_.push_back(std::move(g));
    }
  }

  void Forward() {
    for (size_t c = 0; c < layers_.size(); ++c) layers_[c]->Forward(inputs_[c]);
  }
  void Backward() {
    for (size_t c = 0; c < layers_.size(); ++c) {
      if (first_[c]) {
        layers_[c]->BackwardParams(grads_[c]);
      } else {
        layers_[c]->Backward(grads_[c]);
      }
    }
  }

 private:
  std::vector<std::unique_ptr<rl::nn::Conv2d>> layers_;
  std::vector<Matrix> inputs_;
  std::vector<Matrix> grads_;
  std::vector<bool> first_;
};

// Median time of one action for a uint8 observation, including its conversion to x/255
// (micro.py's latency: from_numpy, forward with x.float() / 255, argmax, item), timing each call:
// the greedy action of a Q network (`greedy`), or the actor's output (Predict).
struct Latency {
  double median_ms = 0;
  double mean_ms = 0;
};

Latency MeasureLatency(Sequential* net, const std::vector<uint8_t>& obs, bool greedy,
                       double seconds) {
  const int size = net->InputSize();
  Matrix x;
  int sink = 0;
  auto act = [&] {
    rl::nn::PixelsToMatrix(obs.data(), size, 1, &x);
    sink += greedy ? net->Argmax(x.data(), size) : net->Predict(x.data(), size)(0, 0) > 0.0f;
  };
  for (int i = 0; i < 3; ++i) act();
  std::vector<double> ms;
  ms.reserve(1 << 16);
  const auto start = Clock::now();
  do {
    const auto t0 = Clock::now();
    act();
    const auto t1 = Clock::now();
    ms.push_back(std::chrono::duration<double, std::milli>(t1 - t0).count());
  } while (std::chrono::duration<double>(Clock::now() - start).count() < seconds || ms.size() < 20);
  Latency l;
  for (double v : ms) l.mean_ms += v;
  l.mean_ms /= static_cast<double>(ms.size());
  l.median_ms = rl::bench::Summarize(ms).median;
  if (sink < 0) std::printf("%d\n", sink);  // Keeps the calls.
  return l;
}

// The peak loop compiled for the baseline (256-bit FMA) and, below, for AVX-512 with
// AVX512_BF16 (called only on CPUs that have them: nn::RunnableKernelPaths()).
namespace baseline {
#include "bench/peak_loop.h"

double Fma256Gflops(double seconds) {
  const __m256 mul = _mm256_set1_ps(0.999999f);
  const __m256 add = _mm256_set1_ps(1e-6f);
  return ChainGflops<8>(
      _mm256_set1_ps(1.0f), [&](__m256 x) { return _mm256_fmadd_ps(x, mul, add); }, 2, seconds);
}
}  // namespace baseline

RL_NN_TARGET_BEGIN("avx2,fma,avx512f,avx512vl,avx512bf16")
namespace wide {
#include "bench/peak_loop.h"

double Fma512Gflops(double seconds) {
  const __m512 mul = _mm512_set1_ps(0.999999f);
  const __m512 add = _mm512_set1_ps(1e-6f);
  return ChainGflops<16>(
      _mm512_set1_ps(1.0f), [&](__m512 x) { return _mm512_fmadd_ps(x, mul, add); }, 2, seconds);
}

// acc += 1 * 2^-20 + 1 * 2^-20 per lane (bf16 pairs 0x3F80 = 1 and 0x3580 = 2^-20).
double Bf16Dot512Gflops(double seconds) {
  const auto ones = (__m512bh)_mm512_set1_epi32(0x3F803F80);
  const auto tiny = (__m512bh)_mm512_set1_epi32(0x35803580);
  return ChainGflops<16>(
      _mm512_setzero_ps(), [&](__m512 x) { return _mm512_dpbf16_ps(x, ones, tiny); }, 4, seconds);
}

double Bf16Dot256Gflops(double seconds) {
  const auto ones = (__m256bh)_mm256_set1_epi32(0x3F803F80);
  const auto tiny = (__m256bh)_mm256_set1_epi32(0x35803580);
  return ChainGflops<8>(
      _mm256_setzero_ps(), [&](__m256 x) { return _mm256_dpbf16_ps(x, ones, tiny); }, 4, seconds);
}
}  // namespace wide
RL_NN_TARGET_END

bool CpuRuns(const std::string& path) {
  const std::vector<std::string> paths = rl::nn::RunnableKernelPaths();
  return std::find(paths.begin(), paths.end(), path) != paths.end();
}

// The sum of `measure` over `threads` threads running it at the same time.
double OnThreads(int threads, const std::function<double()>& measure) {
  std::vector<double> rates(static_cast<size_t>(threads));
  std::vector<std::thread> pool;
  for (int t = 1; t < threads; ++t) {
    pool.emplace_back([&, t] { rates[static_cast<size_t>(t)] = measure(); });
  }
  rates[0] = measure();
  for (std::thread& t : pool) t.join();
  double sum = 0;
  for (double r : rates) sum += r;
  return sum;
}

// The peak rows of one thread count (see the top of this file); returns the fp32 and bf16 peaks
// (0 where the CPU has no bf16 instruction).
struct Peaks {
  double fp32 = 0;
  double bf16 = 0;
};
Peaks MeasurePeaks(int threads, int repeats, double seconds) {
  const double s = std::min(seconds, 0.5);
  auto emit = [&](const char* name, int bits, double (*wide_fn)(double),
                  double (*narrow_fn)(double), const std::string& method) {
    std::vector<double> v, narrow;
    for (int r = 0; r < repeats; ++r) {
      v.push_back(OnThreads(threads, [&] { return wide_fn(s); }));
      if (threads == 1) narrow.push_back(narrow_fn(s));
    }
    const rl::bench::Summary peak = rl::bench::Summarize(v);
    rl::bench::Emit(
        name, "GFLOP/s", peak, repeats,
        "\"threads\": " + std::to_string(threads) + ", \"threads_used\": " +
            std::to_string(threads) + ", \"cores\": " + std::to_string(threads) +
            ", \"per_core\": " + Num(peak.median / threads) + ", \"vector_bits\": " +
            std::to_string(bits) + ", \"method\": \"" + std::to_string(bits == 512 ? 16 : 12) +
            " " + "independent chains of " + std::to_string(bits) + "-bit " + method +
            " on each of " + std::to_string(threads) + " threads at once\"" +
            (narrow.empty() ? ""
                            : ", \"gflops_256bit\": " + Num(rl::bench::Summarize(narrow).median)));
    return peak.median;
  };
  Peaks p;
  if (CpuRuns("avx512")) {
    p.fp32 = emit("peak_fp32_gflops", 512, &wide::Fma512Gflops, &baseline::Fma256Gflops,
                  "FMA instructions; 2 FLOPs per lane and FMA");
  } else {
    p.fp32 = emit("peak_fp32_gflops", 256, &baseline::Fma256Gflops, &baseline::Fma256Gflops,
                  "FMA instructions; 2 FLOPs per lane and FMA");
  }
  if (CpuRuns("avx512_bf16")) {
    p.bf16 = emit("peak_bf16_gflops", 512, &wide::Bf16Dot512Gflops, &wide::Bf16Dot256Gflops,
                  "vdpbf16ps instructions; 4 FLOPs per 32-bit lane (two bf16 products added)");
  } else {
    std::fprintf(stderr, "bench_cnn: no AVX512_BF16 on this CPU: no peak_bf16_gflops row\n");
  }
  return p;
}

// The "threads" fields of a measurement at `threads` threads whose operation ran `sections`
// parallel sections (nn::internal::ParallelSections()): a computation too small to be split runs
// on one thread whatever the setting, and says so.
std::string ThreadFields(int threads, int64_t sections) {
  return "\"threads\": " + std::to_string(threads) +
         ", \"threads_used\": " + std::to_string(sections > 0 ? rl::nn::NumThreads() : 1) +
         ", \"parallel_sections_per_call\": " + std::to_string(sections);
}

// Parallel sections run by one call of `op`.
int64_t SectionsOf(const std::function<void()>& op) {
  const int64_t before = rl::nn::internal::ParallelSections();
  op();
  return rl::nn::internal::ParallelSections() - before;
}

// The non-empty items of a comma-separated list.
std::vector<std::string> SplitCommas(const std::string& text) {
  std::vector<std::string> out;
  std::stringstream ss(text);
  std::string item;
  while (std::getline(ss, item, ',')) {
    if (!item.empty()) out.push_back(item);
  }
  return out;
}

std::vector<int> ParseThreads(const std::string& arg) {
  std::vector<int> out;
  for (const std::string& item : SplitCommas(arg)) out.push_back(std::atoi(item.c_str()));
  return out;
}

// The fields of a network line: its name, batch, precision and kernels.
std::string NetFields(const std::string& net, int batch, rl::nn::Precision precision) {
  return "\"net\": \"" + net + "\", \"batch\": " + std::to_string(batch) + ", \"precision\": \"" +
         rl::nn::PrecisionName(precision) + "\", \"kernels\": \"" + rl::nn::KernelPath() +
         "\", \"bf16_native\": " + (rl::nn::NativeBf16() ? "true" : "false");
}

// 1. DQN updates per second.
void BenchUpdates(const NetSpec& spec, const Sequential& net, rl::nn::Precision precision,
                  int threads, int repeats, double seconds, std::mt19937* rng) {
  const Flops flops = CountFlops(net, kBatch);
  DqnUpdate update(net, kBatch, rng);
  for (int i = 0; i < 3; ++i) update.Run();
  const int64_t sections = SectionsOf([&] { update.Run(); });
  const rl::bench::Summary s = rl::bench::Repeat(
      repeats, [&] { return rl::bench::Rate([&] { update.Run(); }, 1, seconds, 1); });
  rl::bench::Emit(
      "learner_updates_" + spec.name, "updates/s", s, repeats,
      NetFields(spec.name, kBatch, precision) + ", \"actions\": " + std::to_string(kActions) +
          ", " + ThreadFields(threads, sections) +
          ", \"loss\": \"huber\", \"optimizer\": \"adam\"" + ", \"gflop_per_update\": " +
          Num(flops.Update() / 1e9) + ", \"gflops\": " + Num(flops.Update() / 1e9 * s.median) +
          ", \"conv_gflop_per_update\": " + Num(flops.ConvUpdate() / 1e9) +
          ", \"peer_mode\": \"micro.py " + (spec.name == "nature_cnn" ? "nature" : "small") +
          "\", \"work\": \"" + kUpdateWork + "\"");
}

// 2. Latency of one action for one observation: the greedy action of a Q network, or an actor's
// output.
void BenchLatency(const std::string& name, const Sequential& net, bool greedy, bool peer,
                  rl::nn::Precision precision, int threads, int repeats, double seconds) {
  Sequential actor = net;
  std::mt19937 obs_rng(0);
  const std::vector<uint8_t> obs = RandomPixels(static_cast<size_t>(actor.InputSize()), &obs_rng);
  const int64_t sections = SectionsOf([&] {
    Matrix x;
    rl::nn::PixelsToMatrix(obs.data(), actor.InputSize(), 1, &x);
    actor.Predict(x.data(), actor.InputSize());
  });
  std::vector<double> medians;
  double mean = 0;
  for (int r = 0; r < repeats; ++r) {
    const Latency l = MeasureLatency(&actor, obs, greedy, seconds);
    medians.push_back(l.median_ms);
    mean += l.mean_ms / repeats;
  }
  rl::bench::Emit(
      "inference_latency_" + name, "ms", rl::bench::Summarize(medians), repeats,
      NetFields(name, 1, precision) + ", " + ThreadFields(threads, sections) +
          ", \"statistic\": \"median over calls (per repeat)\", \"mean_ms\": " + Num(mean) +
          ", \"work\": \"uint8 observation to x/255 (PixelsToMatrix), forward in evaluation "
          "mode, " +
          (greedy ? "argmax (Sequential::Argmax)" : "the action (Sequential::Predict)") + "\"" +
          (peer ? ", \"peer_mode\": \"micro.py latency\"" : ""));
}

// 3. GFLOP/s of the convolution layers alone.
void BenchConvPasses(const NetSpec& spec, const Sequential& net, rl::nn::Precision precision,
                     const Peaks& peaks, int threads, int repeats, double seconds,
                     std::mt19937* rng) {
  const Flops flops = CountFlops(net, kBatch);
  ConvStack convs(net, kBatch, precision, rng);
  convs.Forward();
  convs.Backward();
  struct Pass {
    const char* name;
    double flops;
    std::function<void()> run;
  };
  const Pass passes[] = {
      {"forward", flops.conv_forward, [&] { convs.Forward(); }},
      {"backward", flops.conv_backward, [&] { convs.Backward(); }},
      {"update", flops.ConvUpdate(),
       [&] {
         convs.Forward();
         convs.Forward();
         convs.Backward();
       }},
  };
  const double peak =
      precision == rl::nn::Precision::kBf16 && peaks.bf16 > 0 ? peaks.bf16 : peaks.fp32;
  for (const Pass& pass : passes) {
    const int64_t sections = SectionsOf(pass.run);
    const rl::bench::Summary s = rl::bench::Repeat(
        repeats, [&] { return pass.flops / 1e9 * rl::bench::Rate(pass.run, 1, seconds, 1); });
    rl::bench::Emit(
        "conv_gflops_" + spec.name, "GFLOP/s", s, repeats,
        NetFields(spec.name, kBatch, precision) + ", " + ThreadFields(threads, sections) +
            ", \"pass\": \"" + pass.name + "\", \"gflop_per_call\": " + Num(pass.flops / 1e9) +
            ", \"peak_gflops\": " + Num(peak) + ", \"fraction_of_peak\": " + Num(s.median / peak) +
            ", \"fraction_of_fp32_peak\": " + Num(s.median / peaks.fp32));
  }
}

}  // namespace

int main(int argc, char** argv) {
  const rl::bench::Args args(
      argc, argv,
      "usage: bench_cnn [REPEATS (5)] [SECONDS per repeat (1)] [THREADS (1,2)] [WHAT]\n"
      "Pixel networks' updates/s, latency and GFLOP/s against the machine's "
      "peaks (JSON lines). WHAT: a comma-separated subset of nature_cnn, grasp_cnn and "
      "actors (the TD3 actors' latency), all by default.",
      4);
  const int repeats = args.Int(0, 5);
  const double seconds = args.Number(1, 1.0);
  const std::vector<int> thread_counts = ParseThreads(args.Text(2, "1,2"));
  const std::vector<std::string> what = SplitCommas(args.Text(3, "nature_cnn,grasp_cnn,actors"));
  if (what.empty()) args.Fail("WHAT names nothing to measure");
  for (const std::string& item : what) {
    if (item != "nature_cnn" && item != "grasp_cnn" && item != "actors") {
      args.Fail("WHAT is a list of nature_cnn, grasp_cnn and actors, not '" + item + "'");
    }
  }
  const auto wanted = [&what](const std::string& name) {
    return std::find(what.begin(), what.end(), name) != what.end();
  };
  if (thread_counts.empty() ||
      std::any_of(thread_counts.begin(), thread_counts.end(), [](int t) { return t < 1; })) {
    args.Fail("THREADS is a list of thread counts, e.g. 1,2");
  }
  const std::vector<NetSpec> nets = {
      {"nature_cnn", "nature_cnn",
       [](std::mt19937* rng) { return rl::nn::MakeNatureCnn(kActions, rng); }},
      {"grasp_cnn", "small_cnn_bn",
       [](std::mt19937* rng) { return rl::nn::MakeGraspCnn(kActions, rng); }},
  };
  // The CarRacing actors of TD3 (3-d actions: steering, gas, brake), for their latency.
  const std::vector<float> low = {-1.0f, 0.0f, 0.0f};
  const std::vector<float> high = {1.0f, 1.0f, 1.0f};
  const std::vector<std::pair<std::string, std::string>> actors = {
      {"td3_car_actor", rl::nn::Td3CarActorArchitecture(low, high)},
      {"td3_drq_actor",
       rl::nn::CarEncoderArchitecture() + "," + rl::nn::DrqActorHeadArchitecture(256, low, high)},
  };
  const rl::nn::Precision precisions[] = {rl::nn::Precision::kFp32, rl::nn::Precision::kBf16};

  for (int threads : thread_counts) {
    rl::nn::SetNumThreads(threads);
    const Peaks peaks = MeasurePeaks(threads, repeats, seconds);
    for (const NetSpec& spec : nets) {
      if (!wanted(spec.name)) continue;
      for (const rl::nn::Precision precision : precisions) {
        std::mt19937 rng(1);
        Sequential net = spec.make(&rng);
        net.set_precision(precision);
        BenchUpdates(spec, net, precision, threads, repeats, seconds, &rng);
        BenchLatency(spec.name, net, /*greedy=*/true, spec.peer_net == "nature_cnn", precision,
                     threads, repeats, seconds);
        BenchConvPasses(spec, net, precision, peaks, threads, repeats, seconds, &rng);
      }
    }
    for (const auto& [name, arch] : actors) {
      if (!wanted("actors")) break;
      for (const rl::nn::Precision precision : precisions) {
        std::mt19937 rng(1);
        Sequential net = rl::nn::BuildFromArchitecture(arch, &rng);
        net.set_precision(precision);
        net.set_training(false);
        BenchLatency(name, net, /*greedy=*/false, /*peer=*/false, precision, threads, repeats,
                     seconds);
      }
    }
  }
  rl::nn::SetNumThreads(1);
  return 0;
}
