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
#include "envs/specs.h"
#include "envs/time_limit.h"

namespace rl::envs {
namespace {

// What an id's pixels keys change in the env under the pipeline: CarRacing's rules.
struct BaseOptions {
  bool lap_ends = true;
  bool off_track = false;
  int off_track_after = 0;  // The no-op frames after every reset, which the rule skips.
};

CarRacingConfig CarRacingRules(bool continuous, const BaseOptions& o) {
  return CarRacingConfig{.continuous = continuous,
                         .lap_ends = o.lap_ends,
                         .off_track = o.off_track,
                         .off_track_after = o.off_track_after};
}

// One registered id and how to build the env under its TimeLimit (MakeBase), whose default
// limit is the id's spec's (envs/specs.h: one table of the limits).
struct Registration {
  std::string_view id;
  std::unique_ptr<Env> (*make)(const BaseOptions&);
};

constexpr std::array kRegistrations = {
    Registration{
        "CartPole-v1",
        [](const BaseOptions&) -> std::unique_ptr<Env> { return std::make_unique<CartPole>(); }},
    Registration{
        "LunarLander-v3",
        [](const BaseOptions&) -> std::unique_ptr<Env> { return std::make_unique<LunarLander>(); }},
    Registration{"LunarLanderContinuous-v3",
                 [](const BaseOptions&) -> std::unique_ptr<Env> {
                   return std::make_unique<LunarLander>(LunarLanderConfig{.continuous = true});
                 }},
    // CarRacing: 1,000 frames; an episode also ends when every tile is visited (unless lap_ends
    // is off), the car leaves the playfield, or (off_track) the track.
    Registration{"CarRacing-v3",
                 [](const BaseOptions& o) -> std::unique_ptr<Env> {
                   return std::make_unique<CarRacing>(CarRacingRules(true, o));
                 }},
    Registration{"CarRacingDiscrete-v3",
                 [](const BaseOptions& o) -> std::unique_ptr<Env> {
                   return std::make_unique<CarRacing>(CarRacingRules(false, o));
                 }},
    Registration{
        "Pendulum-v1",
        [](const BaseOptions&) -> std::unique_ptr<Env> { return std::make_unique<Pendulum>(); }},
    // Every Catch episode ends after 9 steps, so the limit never cuts one short: it only marks
    // the terminating step truncated as well (terminated still means no bootstrapping).
    Registration{
        "Catch-v0",
        [](const BaseOptions&) -> std::unique_ptr<Env> { return std::make_unique<Catch>(); }},
    // KUKA grasping from a camera: 15 steps on the training objects; the held-out test objects
    // with the 20 steps of evaluation. An episode also ends at its grasp attempt.
    Registration{"KukaDiverseObjectGrasping-v0",
                 [](const BaseOptions&) -> std::unique_ptr<Env> {
                   return std::make_unique<KukaDiverseObjectEnv>();
                 }},
    Registration{"KukaDiverseObjectGraspingTest-v0",
                 [](const BaseOptions&) -> std::unique_ptr<Env> {
                   return std::make_unique<KukaDiverseObjectEnv>(
                       KukaDiverseObjectConfig{.is_test = true, .max_steps = 20});
                 }},
};

// A registered env with its time limit: `time_limit` when positive, else its spec's.
std::unique_ptr<Env> MakeBase(const std::string& id, int time_limit, const BaseOptions& options) {
  for (const Registration& r : kRegistrations) {
    if (r.id == id) {
      return std::make_unique<TimeLimit>(
          r.make(options), time_limit > 0 ? time_limit : LookupSpec(id).max_episode_steps);
    }
  }
  std::string known;
  for (const std::string& name : RegisteredEnvs()) {
    known += known.empty() ? name : ", " + name;
  }
  throw std::invalid_argument("MakeEnv: unknown environment id \"" + id +
                              "\"; known ids: " + known);
}

}  // namespace

std::unique_ptr<Env> MakeEnv(const std::string& id) {
  const EnvIdParts parts = ParseEnvId(id);
  if (!parts.pixels) return MakeBase(id, 0, {});
  const BaseOptions options{.lap_ends = parts.lap_ends,
                            .off_track = parts.off_track,
                            .off_track_after = parts.image.noop_start};
  return MakePixelEnv(MakeBase(parts.base, parts.image.time_limit, options), parts.image);
}

std::vector<std::string> RegisteredEnvs() {
  std::vector<std::string> ids;
  for (const Registration& r : kRegistrations) ids.emplace_back(r.id);
  std::sort(ids.begin(), ids.end());
  return ids;
}

}  // namespace rl::envs
