// CartPole-v1 env steps per second with a random policy (resets included), one thread.
// The same measurement as the PyTorch peer's "env_steps".
#include <random>

#include "bench/bench_util.h"
#include "envs/registry.h"

int main(int argc, char** argv) {
  const int repeats = argc > 1 ? std::atoi(argv[1]) : 5;
  const double seconds = argc > 2 ? std::atof(argv[2]) : 1.0;
  auto env = rl::envs::MakeEnv("CartPole-v1");
  env->Reset(0);
  std::mt19937_64 rng(0);
  const int chunk = 10000;
  const auto s = rl::bench::Repeat(repeats, [&] {
    return rl::bench::Rate(
        [&] {
          for (int i = 0; i < chunk; ++i) {
            const auto r = env->Step(static_cast<int>(rng() & 1U));
            if (r.terminated || r.truncated) env->Reset();
          }
        },
        chunk, seconds);
  });
  rl::bench::Emit("cartpole_env_steps", "steps/s", s, repeats);
  return 0;
}
