// The factories of the registered envs, one for each entry of env_list.inc (the one list of the
// envs: id, factory, spec). Each is defined in its env's own source and called only by MakeEnv
// (registry.h), which wraps the env in its TimeLimit; include this header in the source that
// defines one.
#pragma once

#include <memory>

#include "envs/env.h"
#include "envs/pixel_spec.h"

namespace rl::envs {

/// A registered id's env, not yet reset and without its time limit. `id` is the parsed id
/// (ParseEnvId): id.base is the registered id; CarRacing's factories read its rules (off_track,
/// lap_ends, image.noop_start); the others ignore it.
using EnvFactory = std::unique_ptr<Env> (*)(const EnvIdParts& id);

#define RL_ENV(env_id, factory, ...) std::unique_ptr<Env> factory(const EnvIdParts& id);
#include "envs/env_list.inc"
#undef RL_ENV

}  // namespace rl::envs
