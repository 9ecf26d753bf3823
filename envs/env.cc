#include "envs/env.h"

#include <limits>
#include <stdexcept>
#include <string>

#include "common/check.h"
#include "envs/raster.h"

namespace rl::envs {

StepResult Env::StepContinuous(std::span<const float> /*action*/) {
  throw std::logic_error("discrete env");
}

StepResult Env::Act(std::span<const float> action) {
  const EnvSpec& s = spec();
  // Bounds are the env's to clip; everything else about the action must be right.
  if (const char* why = CheckAction(s, action, std::numeric_limits<float>::infinity())) {
    throw std::invalid_argument(s.id + ": " + why);
  }
  if (s.continuous()) return StepContinuous(action);
  return Step(static_cast<int>(action[0]));
}

std::span<const uint8_t> Env::frame() const { throw std::logic_error("not a pixel env"); }

void Env::RenderSized(int width, int height, std::vector<uint8_t>* rgb) const {
  RL_CHECK(rgb != nullptr) << "RenderSized needs an output buffer";
  if (width <= 0 || height <= 0) {
    throw std::invalid_argument("RenderSized: width and height must be positive, got " +
                                std::to_string(width) + "x" + std::to_string(height));
  }
  std::vector<uint8_t> native;
  int native_width = 0;
  int native_height = 0;
  Render(&native, &native_width, &native_height);
  ResizeRgbArea(native, native_width, native_height, width, height, rgb);
}

}  // namespace rl::envs
