// What every env that draws itself at any size does the same way in Render and RenderSized: the
// native-size Render is RenderSized at that size, and RenderSized checks its arguments and that an
// episode has started, with errors that name the env.
#pragma once

#include <cstdint>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "common/check.h"
#include "envs/env.h"

namespace rl::envs {

/// Env::Render for an env whose native size is width x height: env.RenderSized at that size, and
/// the size written to *width and *height.
inline void RenderNative(const Env& env, int native_width, int native_height,
                         std::vector<uint8_t>* rgb, int* width, int* height) {
  RL_CHECK(width != nullptr && height != nullptr) << "Render needs width and height outputs";
  env.RenderSized(native_width, native_height, rgb);
  *width = native_width;
  *height = native_height;
}

/// RenderSized's arguments: an output buffer (a programming error otherwise) and
/// std::invalid_argument("<name>: render size must be positive, got WxH").
inline void CheckRenderSize(std::string_view name, int width, int height,
                            const std::vector<uint8_t>* rgb) {
  RL_CHECK(rgb != nullptr) << "RenderSized needs an output buffer";
  if (width <= 0 || height <= 0) {
    throw std::invalid_argument(std::string(name) + ": render size must be positive, got " +
                                std::to_string(width) + "x" + std::to_string(height));
  }
}

/// The checks at the top of every env's RenderSized: CheckRenderSize, and
/// std::logic_error("<name>: call Reset() before Render()").
inline void CheckRenderArgs(const Env& env, std::string_view name, int width, int height,
                            const std::vector<uint8_t>* rgb) {
  CheckRenderSize(name, width, height, rgb);
  if (!env.started()) throw std::logic_error(std::string(name) + ": call Reset() before Render()");
}

}  // namespace rl::envs
