// Creates environments by their Gymnasium id, with the time limit that gymnasium.make applies.
// The ids, their specs and their factories are the entries of the list of envs (env_list.inc).
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "envs/env.h"

namespace rl::envs {

/// Creates a fresh, not yet reset env for a registered id. "CartPole-v1" gives
/// TimeLimit(CartPole, 500); "LunarLander-v3" and "LunarLanderContinuous-v3" give
/// TimeLimit(LunarLander, 1000); "Catch-v0" gives TimeLimit(Catch, 9). An id followed by
/// "+pixels(...)" gives that env behind the image pipeline (see pixel_spec.h). Throws
/// std::invalid_argument naming the known ids for an unknown id, or naming a bad pixels setting.
std::unique_ptr<Env> MakeEnv(const std::string& id);

/// The registered ids, sorted.
std::vector<std::string> RegisteredEnvs();

}  // namespace rl::envs
