#include "envs/env.h"

#include <cmath>
#include <cstddef>
#include <sstream>
#include <stdexcept>
#include <string>

#include "common/check.h"
#include "envs/raster.h"
#include "envs/render_args.h"

namespace rl::envs {

namespace {

// Why Step refuses `action`, or nullptr: CheckAction's reasons, except that a continuous env
// clips any value that is not NaN (an infinite value becomes its bound).
const char* StepActionError(const EnvSpec& spec, std::span<const float> action) {
  if (!spec.continuous()) return CheckAction(spec, action);
  if (static_cast<int>(action.size()) != spec.action_width()) return "action of the wrong width";
  for (float a : action) {
    if (std::isnan(a)) return "action is NaN";
  }
  return nullptr;
}

// The action as text for an error message: "[v0, v1, ...]", the first 8 values at most.
std::string ActionText(std::span<const float> action) {
  std::ostringstream text;
  text << '[';
  for (std::size_t i = 0; i < action.size() && i < 8; ++i) text << (i > 0 ? ", " : "") << action[i];
  if (action.size() > 8) text << ", ...";
  text << ']';
  return text.str();
}

}  // namespace

void Env::StartEpisode(std::optional<uint64_t> seed) {
  // An episode whose start throws has not started.
  started_ = false;
  elapsed_steps_ = 0;
  OnReset(seed);
  started_ = true;
}

StepResult Env::Step(std::span<const float> action) {
  if (const char* why = StepActionError(spec_, action)) {
    throw std::invalid_argument(spec_.id + ": " + why + " (got " + ActionText(action) + ")");
  }
  if (!started_) throw std::logic_error(spec_.id + ": call Reset() before Step()");
  ++elapsed_steps_;
  try {
    return OnStep(action);
  } catch (...) {
    --elapsed_steps_;
    throw;
  }
}

void SeededEnv::OnReset(std::optional<uint64_t> seed) {
  if (seed.has_value()) {
    rng_.Seed(*seed);
  } else {
    rng_.SeedIfUnseeded();
  }
  NewEpisode();
}

std::span<const uint8_t> Env::frame() const { throw std::logic_error("not a pixel env"); }

void Env::RenderSized(int width, int height, std::vector<uint8_t>* rgb) const {
  CheckRenderSize("RenderSized", width, height, rgb);
  std::vector<uint8_t> native;
  int native_width = 0;
  int native_height = 0;
  Render(&native, &native_width, &native_height);
  ResizeRgbArea(native, native_width, native_height, width, height, rgb);
}

}  // namespace rl::envs
