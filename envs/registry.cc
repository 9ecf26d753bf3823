#include "envs/registry.h"

#include <algorithm>
#include <array>
#include <stdexcept>
#include <string_view>

#include "envs/env_list.h"
#include "envs/image/pixel_env.h"
#include "envs/pixel_spec.h"
#include "envs/specs.h"
#include "envs/time_limit.h"

namespace rl::envs {
namespace {

// One registered id and the factory of its env (env_list.inc, the one list of the envs).
struct Registration {
  std::string_view id;
  EnvFactory make;
};

constexpr std::array kRegistrations = {
#define RL_ENV(env_id, factory, ...) Registration{env_id, factory},
#include "envs/env_list.inc"
#undef RL_ENV
};

// The registered env of `parts.base` with its time limit: `time_limit` when positive, else its
// spec's.
std::unique_ptr<Env> MakeBase(const EnvIdParts& parts, int time_limit) {
  for (const Registration& r : kRegistrations) {
    if (r.id == parts.base) {
      return std::make_unique<TimeLimit>(
          r.make(parts), time_limit > 0 ? time_limit : LookupSpec(parts.base).max_episode_steps);
    }
  }
  std::string known;
  for (const std::string& name : RegisteredEnvs()) {
    known += known.empty() ? name : ", " + name;
  }
  throw std::invalid_argument("MakeEnv: unknown environment id \"" + parts.base +
                              "\"; known ids: " + known);
}

}  // namespace

std::unique_ptr<Env> MakeEnv(const std::string& id) {
  const EnvIdParts parts = ParseEnvId(id);
  if (!parts.pixels) return MakeBase(parts, 0);
  return MakePixelEnv(MakeBase(parts, parts.image.time_limit), parts.image);
}

std::vector<std::string> RegisteredEnvs() {
  std::vector<std::string> ids;
  for (const Registration& r : kRegistrations) ids.emplace_back(r.id);
  std::sort(ids.begin(), ids.end());
  return ids;
}

}  // namespace rl::envs
