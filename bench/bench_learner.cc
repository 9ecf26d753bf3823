// Learner updates per second, one thread, on random data (eight batches cycled), beside the
// PyTorch peer's "updates" rows (bench/peer/micro.py in the shared folder):
//   learner_updates_mlp  DQN on the CartPole MLP (4-120-84-2) at batch 32, 64 and 128: forward of
//                        the target network on s', forward and backward of the online network on
//                        s, Adam step (MSE loss, lr 2.5e-4, max over the target network, no target
//                        refresh during the measurement).
//   learner_updates_td3  TD3 (learner/td3.h) on the peer's two cases: "td3_mlp" (8-d observation,
//                        2-d action, actor and twin critics 256-256, batch 256) and "td3_car" (the
//                        TD3 CarRacing article's networks on 4 x 84 x 84 stacks, 3-d action, batch
//                        128). One call is one critic update; every 2nd also updates the actor and
//                        the targets (policy delay 2), as the peer's. Also the GFLOP/s this
//                        reaches, from the forward multiply-adds of the networks (see Td3Flops),
//                        and "td3_car_drq": the car_racing_td3 preset's network (drq), batch 128,
//                        and "td3_car_preset": the same network as the preset trains it (batch
//                        64), at 1 and 2 threads (nn::SetNumThreads; the preset's learner runs 2),
//                        also with bf16 in the shared encoder only ("encoder_precision").
// Every row is measured in fp32 and in bf16 (nn/precision.h) and says which ("precision"), on
// which kernel path ("kernels") and whether bf16 ran on the CPU's instructions ("bf16_native").
#include <random>
#include <string>
#include <vector>

#include "bench/bench_util.h"
#include "envs/specs.h"
#include "learner/dqn.h"
#include "learner/td3.h"
#include "nn/conv2d.h"
#include "nn/linear.h"
#include "nn/parallel.h"
#include "nn/pixels.h"
#include "nn/precision.h"

namespace {

struct Data {
  rl::nn::Matrix obs, next_obs;
  std::vector<float> action, reward, discount;
};

// Eight batches: observations normal (flat) or uniform bytes / 255 (pixels), actions in the box.
std::vector<Data> MakeData(const rl::envs::EnvSpec& spec, int batch, bool pixels) {
  std::mt19937 rng(1);
  std::normal_distribution<float> normal;
  std::bernoulli_distribution done(0.05);
  std::uniform_int_distribution<int> byte(0, 255);
  std::vector<Data> data(8);
  const int width = spec.action_width();
  for (Data& d : data) {
    for (rl::nn::Matrix* m : {&d.obs, &d.next_obs}) {
      if (pixels) {
        std::vector<uint8_t> bytes(static_cast<size_t>(spec.observation_size) * batch);
        for (uint8_t& b : bytes) b = static_cast<uint8_t>(byte(rng));
        rl::nn::PixelsToMatrix(bytes.data(), spec.observation_size, batch, m);
      } else {
        m->resize(spec.observation_size, batch);
        for (Eigen::Index i = 0; i < m->size(); ++i) m->data()[i] = normal(rng);
      }
    }
    for (int i = 0; i < batch; ++i) {
      for (int k = 0; k < width; ++k) {
        if (spec.continuous()) {
          const auto u = static_cast<size_t>(k);
          d.action.push_back(
              std::uniform_real_distribution<float>(spec.action_low[u], spec.action_high[u])(rng));
        } else {
          d.action.push_back(static_cast<float>(rng() % static_cast<unsigned>(spec.num_actions)));
        }
      }
      d.reward.push_back(normal(rng));
      d.discount.push_back(done(rng) ? 0.0f : 0.99f);
    }
  }
  return data;
}

// Multiply-adds of one forward pass of one observation through the products of `arch`
// (convolutions and linear layers).
double ForwardMacs(const std::string& arch) {
  if (arch.empty()) return 0;
  std::mt19937 rng(0);
  const rl::nn::Sequential net = rl::nn::BuildFromArchitecture(arch, &rng);
  double macs = 0;
  for (int i = 0; i < net.num_layers(); ++i) {
    const rl::nn::Layer& layer = net.layer(i);
    if (const auto* conv = dynamic_cast<const rl::nn::Conv2d*>(&layer)) {
      const rl::nn::ImageShape in = conv->input_shape();
      const rl::nn::ImageShape out = conv->output_shape();
      macs += static_cast<double>(out.height) * out.width * out.channels * in.channels *
              conv->kernel() * conv->kernel();
    } else if (dynamic_cast<const rl::nn::Linear*>(&layer) != nullptr) {
      macs += static_cast<double>(layer.input_size()) * layer.output_size();
    }
  }
  return macs;
}

// FLOPs (2 x multiply-adds) of one TD3 update at `batch`, averaged over the policy-delay cycle of
// 2, counting a backward pass as twice its forward: the target actor and both target critics
// forward (A + 2C), both critics forward and backward (6C), and every 2nd update the actor
// forward, Q1 forward and backward, the actor backward ((3A + 3C) / 2): 2.5 A + 9.5 C per
// transition. For the 256-256 networks at batch 256 this is 0.42 GFLOP.
double Td3UpdateFlops(rl::learner::Td3& td3, int batch) {
  const double actor = ForwardMacs(td3.actor().Architecture());
  double critic = 0;
  std::string arch = td3.critic(0).Architecture();
  size_t start = 0;
  for (;;) {
    const size_t bar = arch.find('|', start);
    critic += ForwardMacs(arch.substr(start, bar == std::string::npos ? bar : bar - start));
    if (bar == std::string::npos) break;
    start = bar + 1;
  }
  // A shared encoder (network "drq") runs forward on s and s' and backward once (parameter and
  // input gradients of its second layer; about two forwards): 4 E more, on top of the heads.
  const double encoder = td3.shared_encoder() ? ForwardMacs(td3.encoder().Architecture()) : 0;
  return 2.0 * batch * (4 * encoder + 2.5 * actor + 9.5 * critic);
}

rl::learner::Batch View(const Data& d, int batch, int width) {
  rl::learner::Batch b;
  b.count = batch;
  b.action_width = width;
  b.obs = &d.obs;
  b.next_obs = &d.next_obs;
  b.action = d.action;
  b.reward = d.reward;
  b.discount = d.discount;
  return b;
}

// The fields every row has after its measurement's own.
std::string PrecisionFields(rl::nn::Precision precision) {
  return std::string(", \"precision\": \"") + rl::nn::PrecisionName(precision) +
         "\", \"kernels\": \"" + rl::nn::KernelPath() +
         "\", \"bf16_native\": " + (rl::nn::NativeBf16() ? "true" : "false");
}

const rl::nn::Precision kPrecisions[] = {rl::nn::Precision::kFp32, rl::nn::Precision::kBf16};

}  // namespace

int main(int argc, char** argv) {
  const rl::bench::Timing timing = rl::bench::ReadTiming(
      argc, argv, "bench_learner", "Learner updates/s, fp32 and bf16 (JSON lines).");
  const int repeats = timing.repeats;
  const double seconds = timing.seconds;
  for (const rl::nn::Precision precision : kPrecisions) {
    for (int batch : {32, 64, 128}) {
      rl::learner::DqnConfig c;
      c.hidden = {120, 84};
      c.loss = "mse";
      c.learning_rate = 2.5e-4f;
      c.double_dqn = false;
      c.max_grad_norm = 0;
      c.target_update_period = 1 << 30;
      c.precision = precision;
      rl::learner::Dqn dqn(4, 2, c);
      const std::vector<Data> data = MakeData(rl::envs::CartPoleSpec(), batch, false);
      size_t k = 0;
      const auto s = rl::bench::Repeat(repeats, [&] {
        return rl::bench::Rate([&] { dqn.Update(View(data[k++ % data.size()], batch, 1)); }, 1,
                               seconds, 20);
      });
      rl::bench::Emit(
          "learner_updates_mlp", "updates/s", s, repeats,
          "\"batch\": " + std::to_string(batch) + ", \"threads\": 1" + PrecisionFields(precision));
    }
  }

  struct Td3Case {
    const char* name;
    rl::envs::EnvSpec spec;
    std::string network;
    int batch;
    float actor_lr, critic_lr, tau;
    bool pixels;
    int threads = 1;
  };
  rl::envs::EnvSpec mlp_spec = rl::envs::LunarLanderSpec(true);  // 8-d observation, 2-d action
  rl::envs::EnvSpec car_spec = rl::envs::CarRacingSpec(true);    // 3-d action
  car_spec.observation_size = 4 * 84 * 84;
  car_spec.frame_stack = 4;
  car_spec.frame_height = car_spec.frame_width = 84;
  const Td3Case cases[] = {
      {"td3_mlp", mlp_spec, "mlp", 256, 3e-4f, 3e-4f, 0.005f, false},
      {"td3_car", car_spec, "car", 128, 2.5e-4f, 1e-3f, 0.05f, true},
      // The car_racing_td3 preset: the article's encoder shared, DrQ-v2 heads of 256.
      {"td3_car_drq", car_spec, "drq", 128, 2.5e-4f, 1e-3f, 0.05f, true},
      // As configs/car_racing_td3.ini trains it: batch 64, rates 3e-4, tau 0.01, 2 threads
      // (with 3 actions: the preset's pedals=1 drives 2, one output of the heads fewer).
      {"td3_car_preset", car_spec, "drq", 64, 3e-4f, 3e-4f, 0.01f, true, 1},
      {"td3_car_preset", car_spec, "drq", 64, 3e-4f, 3e-4f, 0.01f, true, 2},
  };
  struct Variant {
    rl::nn::Precision precision;
    const char* encoder_precision;  // "": as precision
  };
  const Variant variants[] = {{rl::nn::Precision::kFp32, ""},
                              {rl::nn::Precision::kBf16, ""},
                              {rl::nn::Precision::kFp32, "bf16"}};
  for (const Td3Case& t : cases) {
    for (const auto& [precision, encoder_precision] : variants) {
      const bool own_encoder = *encoder_precision != '\0';
      if (own_encoder && t.network != "drq") continue;
      rl::learner::Td3Config c;
      c.network = t.network;
      c.hidden = {256, 256};
      c.actor_learning_rate = t.actor_lr;
      c.critic_learning_rate = t.critic_lr;
      c.tau = t.tau;
      c.precision = precision;
      c.encoder_precision = encoder_precision;
      rl::nn::SetNumThreads(t.threads);
      rl::learner::Td3 td3(t.spec, c);
      const std::vector<Data> data = MakeData(t.spec, t.batch, t.pixels);
      const int width = t.spec.action_width();
      size_t k = 0;
      const auto s = rl::bench::Repeat(repeats, [&] {
        return rl::bench::Rate([&] { td3.Update(View(data[k++ % data.size()], t.batch, width)); },
                               1, seconds, 4);
      });
      const double gflop = Td3UpdateFlops(td3, t.batch) / 1e9;
      rl::bench::Emit(
          "learner_updates_td3", "updates/s", s, repeats,
          "\"net\": \"" + std::string(t.name) + "\", \"batch\": " + std::to_string(t.batch) +
              ", \"threads\": " + std::to_string(t.threads) +
              ", \"gflop_per_update\": " + std::to_string(gflop) +
              ", \"gflops\": " + std::to_string(gflop * s.median) + PrecisionFields(precision) +
              (own_encoder ? ", \"encoder_precision\": \"" + std::string(encoder_precision) + "\""
                           : ""));
    }
  }
  rl::nn::SetNumThreads(1);
  return 0;
}
