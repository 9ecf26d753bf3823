// Copies of spans as vectors, to compare an env's observation or frame with expected values (and
// print both when they differ).
#pragma once

#include <cstdint>
#include <span>
#include <vector>

namespace rl::envs {

inline std::vector<float> Floats(std::span<const float> values) {
  return {values.begin(), values.end()};
}

inline std::vector<uint8_t> Bytes(std::span<const uint8_t> image) {
  return {image.begin(), image.end()};
}

}  // namespace rl::envs
