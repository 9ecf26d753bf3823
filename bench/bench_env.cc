// Env steps per second with a uniformly random policy (resets included), one thread, for
// CartPole-v1 (the same measurement as the PyTorch peer's "env_steps") and LunarLander-v3.
#include <random>
#include <utility>

#include "bench/bench_util.h"
#include "envs/registry.h"

int main(int argc, char** argv) {
  const int repeats = argc > 1 ? std::atoi(argv[1]) : 5;
  const double seconds = argc > 2 ? std::atof(argv[2]) : 1.0;
  for (const auto& [id, name] : {std::pair{"CartPole-v1", "cartpole_env_steps"},
                                 std::pair{"LunarLander-v3", "lunar_lander_env_steps"}}) {
    auto env = rl::envs::MakeEnv(id);
    const auto actions = static_cast<uint64_t>(env->spec().num_actions);
    env->Reset(0);
    std::mt19937_64 rng(0);
    const int chunk = 10000;
    const auto s = rl::bench::Repeat(repeats, [&] {
      return rl::bench::Rate(
          [&] {
            for (int i = 0; i < chunk; ++i) {
              const auto r = env->Step(static_cast<int>(rng() % actions));
              if (r.terminated || r.truncated) env->Reset();
            }
          },
          chunk, seconds);
    });
    rl::bench::Emit(name, "steps/s", s, repeats);
  }
  return 0;
}
