#include <cmath>
#include <span>

#include "envs/env.h"

namespace rl::envs {

const char* CheckAction(const EnvSpec& spec, std::span<const float> action, float tolerance) {
  if (static_cast<int>(action.size()) != spec.action_width()) {
    return "action of the wrong width";
  }
  for (float a : action) {
    if (!std::isfinite(a)) return "action not finite";
  }
  if (!spec.continuous()) {
    const float a = action[0];
    if (a != std::floor(a)) return "discrete action not an integer";
    if (a < 0 || a >= static_cast<float>(spec.num_actions)) return "discrete action out of range";
    return nullptr;
  }
  for (size_t i = 0; i < action.size(); ++i) {
    if (action[i] < spec.action_low[i] - tolerance || action[i] > spec.action_high[i] + tolerance) {
      return "continuous action outside the bounds";
    }
  }
  return nullptr;
}

}  // namespace rl::envs
