// The demo controller of Gymnasium's lunar_lander.py (its heuristic() function), restated from its
// documented behaviour: a proportional-derivative controller that steers the angle towards the pad
// and holds a descent profile, and only damps the fall once a leg touches. Used by the tests as a
// sanity check of the physics: it lands in most episodes and scores well above 200 on average.
#pragma once

#include <array>
#include <span>

namespace rl::envs {

/// The controller's two errors for an observation (8 values, as LunarLander's).
struct LunarLanderHeuristicErrors {
  double angle_todo = 0;  // Positive: turn counter-clockwise.
  double hover_todo = 0;  // Positive: push up.
};

/// Computes the errors: angle target 0.5 x + vx clipped to [-0.4, 0.4], hover target 0.55 |x|,
/// angle_todo = (angle target - angle) / 2 - angular velocity, hover_todo = (hover target - y) / 2
/// - vy / 2; with any leg contact, angle_todo = 0 and hover_todo = -vy / 2. Throws
/// std::invalid_argument unless the observation has 8 values.
LunarLanderHeuristicErrors ComputeLunarLanderHeuristicErrors(std::span<const float> observation);

/// Discrete action: 2 (main engine) if hover_todo > |angle_todo| and hover_todo > 0.05, else 3
/// (right engine, turns clockwise) if angle_todo < -0.05, else 1 (left engine) if
/// angle_todo > 0.05, else 0.
int LunarLanderHeuristicAction(std::span<const float> observation);

/// Continuous action [hover_todo * 20 - 1, -angle_todo * 20], each clipped to [-1, 1].
std::array<float, 2> LunarLanderHeuristicContinuousAction(std::span<const float> observation);

}  // namespace rl::envs
