#include "envs/registry.h"

#include <algorithm>
#include <array>
#include <stdexcept>
#include <string_view>

#include "envs/box2d/car_racing.h"
#include "envs/box2d/lunar_lander.h"
#include "envs/cartpole.h"
#include "envs/catch.h"
#include "envs/image/pixel_env.h"
#include "envs/kuka/kuka_diverse_object_env.h"
#include "envs/pendulum.h"
#include "envs/pixel_spec.h"
#include "envs/time_limit.h"

namespace rl::envs {
namespace {

// One registered id and how to build it, time limit included.
struct Registration {
  std::string_view id;
  std::unique_ptr<Env> (*make)();
};

constexpr std::array kRegistrations = {
    Registration{"CartPole-v1",
                 []() -> std::unique_ptr<Env> {
                   return std::make_unique<TimeLimit>(std::make_unique<CartPole>(), 500);
                 }},
    Registration{"LunarLander-v3",
                 []() -> std::unique_ptr<Env> {
                   return std::make_unique<TimeLimit>(std::make_unique<LunarLander>(), 1000);
                 }},
    Registration{"LunarLanderContinuous-v3",
                 []() -> std::unique_ptr<Env> {
                   return std::make_unique<TimeLimit>(
                       std::make_unique<LunarLander>(LunarLanderConfig{.continuous = true}), 1000);
                 }},
    // CarRacing: 1,000 frames; an episode also ends when every tile is visited or the car leaves
    // the playfield.
    Registration{"CarRacing-v3",
                 []() -> std::unique_ptr<Env> {
                   return std::make_unique<TimeLimit>(std::make_unique<CarRacing>(), 1000);
                 }},
    Registration{"CarRacingDiscrete-v3",
                 []() -> std::unique_ptr<Env> {
                   return std::make_unique<TimeLimit>(
                       std::make_unique<CarRacing>(CarRacingConfig{.continuous = false}), 1000);
                 }},
    Registration{"Pendulum-v1",
                 []() -> std::unique_ptr<Env> {
                   return std::make_unique<TimeLimit>(std::make_unique<Pendulum>(), 200);
                 }},
    // Every Catch episode ends after 9 steps, so the limit never cuts one short: it only marks
    // the terminating step truncated as well (terminated still means no bootstrapping).
    Registration{"Catch-v0",
                 []() -> std::unique_ptr<Env> {
                   return std::make_unique<TimeLimit>(std::make_unique<Catch>(), 9);
                 }},
    // KUKA grasping from a camera: 15 steps on the training objects; the held-out test objects
    // with the 20 steps of evaluation. An episode also ends at its grasp attempt.
    Registration{"KukaDiverseObjectGrasping-v0",
                 []() -> std::unique_ptr<Env> {
                   return std::make_unique<TimeLimit>(std::make_unique<KukaDiverseObjectEnv>(), 15);
                 }},
    Registration{"KukaDiverseObjectGraspingTest-v0",
                 []() -> std::unique_ptr<Env> {
                   return std::make_unique<TimeLimit>(
                       std::make_unique<KukaDiverseObjectEnv>(
                           KukaDiverseObjectConfig{.is_test = true, .max_steps = 20}),
                       20);
                 }},
};

}  // namespace

std::unique_ptr<Env> MakeEnv(const std::string& id) {
  const EnvIdParts parts = ParseEnvId(id);
  if (parts.pixels) return MakePixelEnv(MakeEnv(parts.base), parts.image);
  for (const Registration& r : kRegistrations) {
    if (r.id == id) return r.make();
  }
  std::string known;
  for (const std::string& name : RegisteredEnvs()) {
    known += known.empty() ? name : ", " + name;
  }
  throw std::invalid_argument("MakeEnv: unknown environment id \"" + id +
                              "\"; known ids: " + known);
}

std::vector<std::string> RegisteredEnvs() {
  std::vector<std::string> ids;
  for (const Registration& r : kRegistrations) ids.emplace_back(r.id);
  std::sort(ids.begin(), ids.end());
  return ids;
}

}  // namespace rl::envs
