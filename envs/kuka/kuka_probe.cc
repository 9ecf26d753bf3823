// kuka_probe: measures KukaDiverseObjectEnv: physics steps/s, rendered frames/s, env steps/s
// with rendering, and the grasp success rates of the scripted oracle and of a random policy.
// Rates are given per second of this process's CPU time (what one actor gets from one free core)
// and per wall-clock second (lower on a busy machine). Where an episode's CPU time goes is split
// into the reset (building the world and settling the dropped objects), the moving steps, the
// grasp (the step that closes the gripper and lifts) and the rendering, each with its physics
// steps.
//
//   kuka_probe [--episodes N] [--test] [--seed S] [--iterations I] [--reference-physics]
//              [--no-render] [--frames F] [--json]
//
// --json prints the figures as JSON lines in the format of the bench/ programs (one measurement
// each, no repeats), which is how scripts/bench.sh reports them.
//
// --test draws held-out objects with 20 steps an episode (evaluation); --reference-physics uses
// the reference's 150 solver iterations and compliant fingertips.
#include <array>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "envs/kuka/kuka_diverse_object_env.h"
#include "envs/kuka/kuka_oracle.h"
#include "envs/rng.h"

namespace {

using Clock = std::chrono::steady_clock;

double Seconds(Clock::time_point a, Clock::time_point b) {
  return std::chrono::duration<double>(b - a).count();
}

// CPU time of this process, seconds.
double CpuSeconds() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

// CPU seconds and physics steps of one part of the episodes.
struct Part {
  double cpu_seconds = 0;
  int64_t physics_steps = 0;
};

struct Rates {
  int episodes = 0;
  int successes = 0;
  int64_t env_steps = 0;
  int64_t physics_steps = 0;
  double seconds = 0;
  double cpu_seconds = 0;
  Part reset, moves, grasp, render;
};

// Runs `episodes` episodes with the oracle (or uniformly random actions), rendering every
// observation at the native size when `render` is set.
Rates Run(rl::envs::KukaDiverseObjectEnv& env, int episodes, uint64_t seed, bool oracle,
          bool render) {
  Rates r;
  std::mt19937_64 rng(seed);
  std::vector<uint8_t> rgb;
  int w = 0, h = 0;
  const auto start = Clock::now();
  const double cpu_start = CpuSeconds();
  // Adds the CPU time since `*cpu` and the physics steps since `*physics` to `part`, and moves
  // both marks on.
  const auto charge = [&env](Part* part, double* cpu, int64_t* physics) {
    const double now = CpuSeconds();
    part->cpu_seconds += now - *cpu;
    part->physics_steps += env.physics_steps() - *physics;
    *cpu = now;
    *physics = env.physics_steps();
  };
  for (int e = 0; e < episodes; ++e) {
    double cpu = CpuSeconds();
    int64_t physics = 0;  // physics_steps() counts from the reset
    env.Reset(seed + e);
    charge(&r.reset, &cpu, &physics);
    if (render) env.Render(&rgb, &w, &h);
    charge(&r.render, &cpu, &physics);
    bool done = false;
    double reward = 0;
    while (!done) {
      const int action = oracle ? rl::envs::kuka::OracleAction(env)
                                : static_cast<int>(rl::envs::UniformInt(rng, 0, 7));
      const rl::envs::StepResult s = env.Step(rl::envs::DiscreteAction(action));
      // The step that closed the gripper and lifted (the episode's last).
      charge(env.attempted_grasp() ? &r.grasp : &r.moves, &cpu, &physics);
      if (render) env.Render(&rgb, &w, &h);
      charge(&r.render, &cpu, &physics);
      reward += s.reward;
      done = s.terminated || s.truncated;
      ++r.env_steps;
    }
    r.physics_steps += env.physics_steps();
    r.successes += reward > 0 ? 1 : 0;
    ++r.episodes;
  }
  r.seconds = Seconds(start, Clock::now());
  r.cpu_seconds = CpuSeconds() - cpu_start;
  return r;
}

// The parts of an episode, named.
std::array<std::pair<const char*, const Part*>, 4> Parts(const Rates& r) {
  return {{{"reset", &r.reset}, {"moves", &r.moves}, {"grasp", &r.grasp}, {"render", &r.render}}};
}

void Print(const char* name, const Rates& r) {
  std::printf(
      "%-7s episodes %d  success %.3f  steps/episode %.2f  physics steps/episode %.0f\n"
      "        per CPU second: env steps %.1f  physics steps %.0f  (per wall second: %.1f, %.0f)\n",
      name, r.episodes, static_cast<double>(r.successes) / r.episodes,
      static_cast<double>(r.env_steps) / r.episodes,
      static_cast<double>(r.physics_steps) / r.episodes, r.env_steps / r.cpu_seconds,
      r.physics_steps / r.cpu_seconds, r.env_steps / r.seconds, r.physics_steps / r.seconds);
  std::printf("        CPU ms per episode (physics steps):");
  for (const auto& [part_name, part] : Parts(r)) {
    std::printf("  %s %.1f (%.0f)", part_name, 1e3 * part->cpu_seconds / r.episodes,
                static_cast<double>(part->physics_steps) / r.episodes);
  }
  std::printf("\n");
}

// The Rates of one policy as JSON lines: env steps/s, physics steps/s and episodes per hour per
// CPU second of one actor, and the success rate.
void PrintJson(const char* policy, const Rates& r, bool test) {
  const char* objects = test ? "held-out" : "training";
  std::printf(
      "{\"bench\": \"kuka_env_steps\", \"value\": %.2f, \"unit\": \"steps/s\", \"policy\": \"%s\", "
      "\"per\": \"cpu second of one actor\", \"wall_value\": %.2f, \"render\": \"48x48 every "
      "step\", "
      "\"objects\": \"%s\", \"episodes\": %d}\n",
      r.env_steps / r.cpu_seconds, policy, r.env_steps / r.seconds, objects, r.episodes);
  std::printf(
      "{\"bench\": \"kuka_physics_steps\", \"value\": %.0f, \"unit\": \"steps/s\", \"policy\": "
      "\"%s\", \"per\": \"cpu second\", \"wall_value\": %.0f}\n",
      r.physics_steps / r.cpu_seconds, policy, r.physics_steps / r.seconds);
  std::printf(
      "{\"bench\": \"kuka_episodes_per_hour_per_actor\", \"value\": %.0f, \"unit\": "
      "\"episodes/h\", "
      "\"policy\": \"%s\", \"steps_per_episode\": %.2f}\n",
      3600.0 * r.episodes / r.cpu_seconds, policy, static_cast<double>(r.env_steps) / r.episodes);
  std::printf(
      "{\"bench\": \"kuka_grasp_success\", \"value\": %.3f, \"unit\": \"fraction\", \"policy\": "
      "\"%s\", \"objects\": \"%s\", \"episodes\": %d}\n",
      static_cast<double>(r.successes) / r.episodes, policy, objects, r.episodes);
  for (const auto& [part_name, part] : Parts(r)) {
    std::printf(
        "{\"bench\": \"kuka_episode_cpu_ms\", \"value\": %.2f, \"unit\": \"ms\", \"policy\": "
        "\"%s\", \"part\": \"%s\", \"physics_steps\": %.0f}\n",
        1e3 * part->cpu_seconds / r.episodes, policy, part_name,
        static_cast<double>(part->physics_steps) / r.episodes);
  }
}

}  // namespace

int main(int argc, char** argv) {
  int episodes = 20;
  int frames = 500;
  uint64_t seed = 1;
  bool render = true;
  bool json = false;
  rl::envs::KukaDiverseObjectConfig config;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--episodes" && i + 1 < argc) {
      episodes = std::atoi(argv[++i]);
    } else if (arg == "--frames" && i + 1 < argc) {
      frames = std::atoi(argv[++i]);
    } else if (arg == "--seed" && i + 1 < argc) {
      seed = std::strtoull(argv[++i], nullptr, 10);
    } else if (arg == "--test") {
      config.is_test = true;
      config.max_steps = 20;
    } else if (arg == "--iterations" && i + 1 < argc) {
      config.solver_iterations = std::atoi(argv[++i]);
    } else if (arg == "--reference-physics") {
      config.solver_iterations = 150;
      config.rigid_fingertips = false;
    } else if (arg == "--no-render") {
      render = false;
    } else if (arg == "--json") {
      json = true;
    } else {
      std::fprintf(stderr,
                   "usage: kuka_probe [--episodes N] [--test] [--seed S] [--iterations I] "
                   "[--reference-physics] [--no-render] [--frames F] [--json]\n");
      return 2;
    }
  }
  rl::envs::KukaDiverseObjectEnv env(config);

  // Rendering alone at the native size.
  env.Reset(seed);
  std::vector<uint8_t> rgb;
  int w = 0, h = 0;
  env.Render(&rgb, &w, &h);
  double c0 = CpuSeconds();
  for (int i = 0; i < frames; ++i) env.Render(&rgb, &w, &h);
  const double fps = frames / (CpuSeconds() - c0);
  const char* lp_threads = std::getenv("LP_NUM_THREADS");
  if (json) {
    std::printf(
        "{\"bench\": \"kuka_render_frames\", \"value\": %.0f, \"unit\": \"frames/s\", \"size\": "
        "\"%dx%d\", \"per\": \"cpu second\", \"llvmpipe_threads\": \"%s\"}\n",
        fps, w, h, lp_threads != nullptr ? lp_threads : "default");
  } else {
    std::printf("render  %dx%d frames per CPU second %.0f (LP_NUM_THREADS=%s)\n", w, h, fps,
                lp_threads);
  }

  // Physics alone: the arm moving over resting (sleeping) objects.
  c0 = CpuSeconds();
  const int64_t before = env.physics_steps();
  env.Step(rl::envs::DiscreteAction(0));
  env.Step(rl::envs::DiscreteAction(0));
  const double physics = (env.physics_steps() - before) / (CpuSeconds() - c0);
  if (!json)
    std::printf("physics (arm moving, objects asleep) steps per CPU second %.0f\n", physics);

  const Rates oracle = Run(env, episodes, seed, true, render);
  const Rates random = Run(env, episodes, seed + 1000000, false, render);
  if (json) {
    PrintJson("oracle", oracle, config.is_test);
    PrintJson("random", random, config.is_test);
  } else {
    Print("oracle", oracle);
    Print("random", random);
  }
  return 0;
}
