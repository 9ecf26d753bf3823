// Actor steps per second with policy inference: the actor's own loop (CartPole-v1, the MLP
// 4-120-84-2 policy, epsilon 0.05, one-step transitions batched and published over LCM's
// in-process transport), one thread. The PyTorch peer's "actor_steps" measures env + policy at
// epsilon 0.05 without any publishing.
#include <random>
#include <vector>

#include "actor/actor.h"
#include "bench/bench_util.h"
#include "common/channels.h"
#include "learner/weights_publisher.h"
#include "nn/sequential.h"

int main(int argc, char** argv) {
  const rl::bench::Timing timing = rl::bench::ReadTiming(
      argc, argv, "bench_actor", "The actor's own loop, steps/s (JSON lines).");
  const int repeats = timing.repeats;
  const double seconds = timing.seconds;
  rl::Bus bus(rl::InProcessBusConfig(1, "actor-0"));
  rl::actor::ActorConfig c;
  c.exploration.mode = "constant";
  c.exploration.end = 0.05;
  c.batch_size = 32;
  rl::actor::Actor actor(c, &bus);
  std::mt19937 rng(0);
  rl::nn::Sequential net = rl::nn::MakeMlp(4, {120, 84}, 2, &rng);
  std::vector<float> flat;
  net.GetFlat(&flat);
  for (auto& chunk : rl::learner::MakeWeightChunks(1, net.Architecture(), flat)) {
    bus.Publish(rl::channels::kWeights, &chunk, rl::Port::kBulk);
  }
  bus.Handle(0);
  if (actor.weights_version() != 1) {
    std::fprintf(stderr, "bench_actor: the actor did not take the weights\n");
    return 1;
  }
  const int chunk = 2000;
  const auto s = rl::bench::Repeat(repeats, [&] {
    return rl::bench::Rate(
        [&] {
          for (int i = 0; i < chunk; ++i) actor.StepEnvs();
          bus.Handle(0);  // deliver (and drop) what was published
        },
        chunk, seconds);
  });
  rl::bench::Emit("actor_steps", "steps/s", s, repeats, "\"net\": \"mlp\", \"epsilon\": 0.05");
  return 0;
}
