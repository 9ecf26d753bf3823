// Static env specs: what every registered env id is (sizes, action space, time limit, goal),
// known without building the env, so that processes that need only sizes (the learner, the
// replay) link no physics or rendering library. The numbers are written once, in the list of
// envs (env_list.inc), which the registry reads too; each env class takes its spec from here.
#pragma once

#include <string>
#include <vector>

#include "envs/env.h"

namespace rl::envs {

struct ImagePipelineConfig;

// Shorthands for LookupSpec of the envs' ids, kept for the code that names them. A new env
// needs none: its class calls LookupSpec(its id).
EnvSpec CartPoleSpec();
EnvSpec CatchSpec();
/// Pendulum-v1 (environments.md 4b); goal -200 (Gymnasium registers none; the usual bar).
EnvSpec PendulumSpec();
EnvSpec LunarLanderSpec(bool continuous);
/// CarRacing-v3 (continuous: steer [-1, 1], gas [0, 1], brake [0, 1]) or its discrete variant
/// "CarRacingDiscrete-v3" (5 actions); observation 96 x 96 x 3 RGB / 255; native render 96 x 96.
/// With `pedals` (continuous only, CarRacingConfig::pedals): steer and pedal, both in [-1, 1].
EnvSpec CarRacingSpec(bool continuous, bool pedals = false);
/// The KUKA grasping envs: training objects or held-out test objects, with `max_steps` as the
/// time limit and a native render size of width x height (the registered ids: 15 and 20 steps,
/// 48 x 48).
EnvSpec KukaDiverseObjectSpec(bool is_test, int max_steps, int width, int height);

/// The spec of `inner` behind the image pipeline `config` (as MakePixelEnv builds it): frame
/// size from the render size, crops and output size; max_episode_steps divided by frame_skip,
/// rounded up. Throws std::invalid_argument when the crops leave no pixel.
EnvSpec PixelSpec(const EnvSpec& inner, const ImagePipelineConfig& config);

/// The spec MakeEnv(id)->spec() has, time limit included, without building anything. Throws
/// std::invalid_argument as MakeEnv does for an unknown id or a bad pixels setting.
EnvSpec LookupSpec(const std::string& id);

/// Whether `a` and `b` give the same observations (size, frame geometry and stack) and the same
/// actions (count, dimension and bounds), so that one's transitions and networks fit the other:
/// an env for another phase of training, or for another metric, of the same run.
bool SameShape(const EnvSpec& a, const EnvSpec& b);

/// The ids LookupSpec knows (those of env_list.inc, without pixel pipelines), sorted: the same
/// list as RegisteredEnvs() (registry.h), which needs the envs linked.
std::vector<std::string> SpecIds();

}  // namespace rl::envs
