#include "envs/box2d/lunar_lander_heuristic.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace rl::envs {

LunarLanderHeuristicErrors ComputeLunarLanderHeuristicErrors(std::span<const float> observation) {
  if (observation.size() != 8) {
    throw std::invalid_argument("LunarLanderHeuristic: the observation must have 8 values, got " +
                                std::to_string(observation.size()));
  }
  const double x = observation[0];
  const double y = observation[1];
  const double vx = observation[2];
  const double vy = observation[3];
  const double angle = observation[4];
  const double angular_velocity = observation[5];
  const bool contact = observation[6] != 0.0f || observation[7] != 0.0f;

  // Lean towards the pad centre (and against the drift), but never more than 0.4 rad; hold a
  // height that grows with the distance from the centre.
  const double angle_target = std::clamp(x * 0.5 + vx * 1.0, -0.4, 0.4);
  const double hover_target = 0.55 * std::abs(x);

  // PD terms on the angle and on the height.
  LunarLanderHeuristicErrors t;
  t.angle_todo = (angle_target - angle) * 0.5 - angular_velocity * 1.0;
  t.hover_todo = (hover_target - y) * 0.5 - vy * 0.5;

  // Once a leg touches, only damp the vertical speed.
  if (contact) {
    t.angle_todo = 0;
    t.hover_todo = -vy * 0.5;
  }
  return t;
}

int LunarLanderHeuristicAction(std::span<const float> observation) {
  const LunarLanderHeuristicErrors t = ComputeLunarLanderHeuristicErrors(observation);
  if (t.hover_todo > std::abs(t.angle_todo) && t.hover_todo > 0.05) return 2;
  if (t.angle_todo < -0.05) return 3;
  if (t.angle_todo > +0.05) return 1;
  return 0;
}

std::array<float, 2> LunarLanderHeuristicContinuousAction(std::span<const float> observation) {
  const LunarLanderHeuristicErrors t = ComputeLunarLanderHeuristicErrors(observation);
  return {static_cast<float>(std::clamp(t.hover_todo * 20 - 1, -1.0, 1.0)),
          static_cast<float>(std::clamp(-t.angle_todo * 20, -1.0, 1.0))};
}

}  // namespace rl::envs
