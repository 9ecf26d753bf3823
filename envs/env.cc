#include "envs/env.h"

#include <stdexcept>
#include <string>

#include "common/check.h"
#include "envs/raster.h"

namespace rl::envs {

StepResult Env::StepContinuous(std::span<const float> /*action*/) {
  throw std::logic_error("discrete env");
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
