#include "envs/image/image_config.h"

#include <cstdint>
#include <stdexcept>
#include <string>

namespace rl::envs {
namespace {

// Throws std::invalid_argument("ImagePipelineConfig: <what>, got <a>x<b>") unless a and b are
// both 0 or both positive.
void CheckSizePair(int a, int b, const char* what) {
  if ((a == 0 && b == 0) || (a > 0 && b > 0)) return;
  throw std::invalid_argument(std::string("ImagePipelineConfig: ") + what + ", got " +
                              std::to_string(a) + "x" + std::to_string(b));
}

// Throws std::invalid_argument naming `field` unless value >= minimum.
void CheckAtLeast(int value, int minimum, const char* field) {
  if (value >= minimum) return;
  throw std::invalid_argument(std::string("ImagePipelineConfig: ") + field + " must be >= " +
                              std::to_string(minimum) + ", got " + std::to_string(value));
}

// Throws std::invalid_argument naming `field` unless value <= maximum.
void CheckAtMost(int value, int maximum, const char* field) {
  if (value <= maximum) return;
  throw std::invalid_argument(std::string("ImagePipelineConfig: ") + field + " must be <= " +
                              std::to_string(maximum) + ", got " + std::to_string(value));
}

// Throws std::invalid_argument unless the two crops of one axis leave at least one of its `size`
// pixels (a 64-bit sum: the crops can be large).
void CheckCropLeavesPixels(int crop_a, int crop_b, int size, const char* crops,
                           const char* size_name) {
  if (int64_t{crop_a} + crop_b < size) return;
  throw std::invalid_argument(std::string("ImagePipelineConfig: ") + crops + " must be below " +
                              size_name + " (" + std::to_string(size) + "), got " +
                              std::to_string(crop_a) + " + " + std::to_string(crop_b));
}

}  // namespace

void ImagePipelineConfig::Validate() const {
  CheckSizePair(render_width, render_height,
                "render_width and render_height must both be 0 (native size) or both positive");
  CheckAtLeast(frame_skip, 1, "frame_skip");
  CheckAtLeast(crop_top, 0, "crop_top");
  CheckAtLeast(crop_bottom, 0, "crop_bottom");
  CheckAtLeast(crop_left, 0, "crop_left");
  CheckAtLeast(crop_right, 0, "crop_right");
  // With an explicit render size the crops can be checked now.
  if (render_width > 0) {
    CheckCropLeavesPixels(crop_left, crop_right, render_width, "crop_left + crop_right",
                          "render_width");
    CheckCropLeavesPixels(crop_top, crop_bottom, render_height, "crop_top + crop_bottom",
                          "render_height");
  }
  CheckSizePair(width, height,
                "width and height must both be 0 (keep the cropped size) or both positive");
  CheckAtLeast(stack, 1, "stack");
  CheckAtLeast(noop_start, 0, "noop_start");
  CheckAtLeast(time_limit, 0, "time_limit");
  CheckAtMost(render_width, kMaxFrameSide, "render_width");
  CheckAtMost(render_height, kMaxFrameSide, "render_height");
  CheckAtMost(width, kMaxFrameSide, "width");
  CheckAtMost(height, kMaxFrameSide, "height");
  CheckAtMost(stack, kMaxFrameStack, "stack");
}

}  // namespace rl::envs
