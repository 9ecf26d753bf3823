// Env steps per second with a uniformly random policy (resets included), one thread, for
// CartPole-v1 (the same measurement as the PyTorch peer's "env_steps") and LunarLander-v3; for
// CarRacing-v3: with every frame drawn at 96 x 96, without drawing, and through the TD3 preset's
// image pipeline (action repeat 5, only the frame an agent sees drawn), in env frames per
// second; and the scripted centre-line pilot's mean score over 100 tracks (the env is solvable),
// also on the discrete variant, deciding every frame and every fifth.
#include <array>
#include <random>
#include <span>
#include <utility>
#include <vector>

#include "bench/bench_util.h"
#include "envs/box2d/car_racing.h"
#include "envs/box2d/car_racing_pilot.h"
#include "envs/registry.h"

namespace {

// CarRacing frames per second with uniformly random actions; `draw` asks for every observation.
double CarRacingRate(rl::envs::Env& env, int frames_per_step, bool draw, double seconds,
                     std::mt19937_64& rng) {
  std::uniform_real_distribution<float> unit(0, 1);
  const int chunk = 2000;
  return rl::bench::Rate(
      [&] {
        for (int i = 0; i < chunk; ++i) {
          const std::array<float, 3> action = {2 * unit(rng) - 1, unit(rng), 0.2f * unit(rng)};
          const auto r = env.Step(action);
          if (draw) (void)env.observation()[0];
          if (r.terminated || r.truncated) env.Reset();
        }
      },
      double{chunk} * frames_per_step, seconds);
}

// The scripted pilot's mean return over 100 tracks (seeds 5000-5099), 1,000 frames at most: with
// the continuous actions, or with the discrete variant's five (gas 0.2, and no action steers and
// accelerates at once), deciding every `repeat` frames (the pixel presets' action repeat is 5).
void PilotScore(bool discrete, int repeat, const char* name) {
  std::vector<double> returns;
  int laps = 0;
  for (uint64_t seed = 5000; seed < 5100; ++seed) {
    rl::envs::CarRacing car(rl::envs::CarRacingConfig{.continuous = !discrete});
    rl::envs::CarRacingPilot pilot;
    car.Reset(seed);
    double total = 0;
    std::array<float, 3> action{};  // [steer, gas, brake], or the discrete index in action[0]
    const std::span<const float> taken = std::span<const float>(action).first(discrete ? 1 : 3);
    for (int frame = 0; frame < 1000; ++frame) {
      if (frame % repeat == 0) {
        if (discrete) {
          action[0] = static_cast<float>(pilot.ActDiscrete(car));
        } else {
          action = pilot.Act(car);
        }
      }
      const auto r = car.Step(taken);
      total += r.reward;
      if (r.terminated) break;
    }
    laps += car.lap_finished();
    returns.push_back(total);
  }
  double mean = 0;
  for (double r : returns) mean += r / returns.size();
  const rl::bench::Summary s = rl::bench::Summarize(returns);
  std::printf(
      "{\"bench\": \"%s\", \"value\": %.1f, \"unit\": \"return\", \"min\": %.1f, "
      "\"median\": %.1f, \"max\": %.1f, \"episodes\": 100, \"laps\": %d, \"repeat\": %d}\n",
      name, mean, s.min, s.median, s.max, laps, repeat);
}

void BenchCarRacing(int repeats, double seconds) {
  std::mt19937_64 rng(0);
  auto env = rl::envs::MakeEnv("CarRacing-v3");
  env->Reset(0);
  rl::bench::Emit(
      "car_racing_env_steps_rendered", "steps/s",
      rl::bench::Repeat(repeats, [&] { return CarRacingRate(*env, 1, true, seconds, rng); }),
      repeats, "\"size\": \"96x96\", \"supersample\": 4");
  rl::bench::Emit(
      "car_racing_env_steps_physics", "steps/s",
      rl::bench::Repeat(repeats, [&] { return CarRacingRate(*env, 1, false, seconds, rng); }),
      repeats);
  auto pixels = rl::envs::MakeEnv(
      "CarRacing-v3+pixels(skip=5,max-pool=0,crop-bottom=12,crop-left=6,crop-right=6,width=0,"
      "height=0,stack=4)");
  pixels->Reset(0);
  rl::bench::Emit(
      "car_racing_pixel_env_frames_skip5", "frames/s",
      rl::bench::Repeat(repeats, [&] { return CarRacingRate(*pixels, 5, true, seconds, rng); }),
      repeats, "\"frames_drawn\": \"1 in 5\", \"observation\": \"4x84x84\"");

  PilotScore(/*discrete=*/false, 1, "car_racing_pilot_score");
  PilotScore(/*discrete=*/true, 1, "car_racing_discrete_pilot_score");
  PilotScore(/*discrete=*/true, 5, "car_racing_discrete_pilot_score");
}

}  // namespace

int main(int argc, char** argv) {
  const rl::bench::Timing timing = rl::bench::ReadTiming(
      argc, argv, "bench_env", "Env steps/s with a random policy (JSON lines).");
  const int repeats = timing.repeats;
  const double seconds = timing.seconds;
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
              const auto r = env->Step(rl::envs::DiscreteAction(static_cast<int>(rng() % actions)));
              if (r.terminated || r.truncated) env->Reset();
            }
          },
          chunk, seconds);
    });
    rl::bench::Emit(name, "steps/s", s, repeats);
  }
  BenchCarRacing(repeats, seconds);
  return 0;
}
