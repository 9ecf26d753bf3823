// A scripted grasping policy for KukaDiverseObjectEnv that reads the simulator's state (object
// poses, the gripper's pose): it moves the grasp point over the nearest reachable object, then
// turns the gripper across the object's longest horizontal extent, and otherwise just lets the
// gripper descend. Used to check that the task is solvable and to measure what a good policy
// reaches; it is not part of the env's interface to agents.
#pragma once

#include "envs/kuka/kuka_diverse_object_env.h"

namespace rl::envs::kuka {

/// Options of OracleAction.
struct OracleOptions {
  bool align_gripper = true;  // Turn the fingers across the object once above it.
};

/// The oracle's action (0..6) in the env's current state. The env must have been reset.
int OracleAction(const KukaDiverseObjectEnv& env, const OracleOptions& options = {});

}  // namespace rl::envs::kuka
