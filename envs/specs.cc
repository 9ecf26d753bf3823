#include "envs/specs.h"

#include <array>
#include <cstdint>
#include <stdexcept>
#include <string_view>

#include "envs/image/image_config.h"
#include "envs/pixel_spec.h"

namespace rl::envs {

EnvSpec CartPoleSpec() {
  return EnvSpec{.id = "CartPole-v1",
                 .observation_size = 4,
                 .num_actions = 2,
                 .max_episode_steps = 500,
                 .reward_threshold = 475.0,
                 .render_width = 600,
                 .render_height = 400};
}

EnvSpec CatchSpec() {
  // A 10 x 5 grid; every episode ends after 9 steps. Rendered at 8 x 8 pixels per cell.
  return EnvSpec{.id = "Catch-v0",
                 .observation_size = 50,
                 .num_actions = 3,
                 .max_episode_steps = 9,
                 .reward_threshold = 0.9,
                 .render_width = 40,
                 .render_height = 80};
}

EnvSpec PendulumSpec() {
  return EnvSpec{.id = "Pendulum-v1",
                 .observation_size = 3,
                 .num_actions = 0,
                 .max_episode_steps = 200,
                 .reward_threshold = -200.0,
                 .action_dim = 1,
                 .action_low = {-2.0f},
                 .action_high = {2.0f},
                 .render_width = 500,
                 .render_height = 500};
}

EnvSpec LunarLanderSpec(bool continuous) {
  EnvSpec spec{.id = continuous ? "LunarLanderContinuous-v3" : "LunarLander-v3",
               .observation_size = 8,
               .num_actions = continuous ? 0 : 4,
               .max_episode_steps = 1000,
               .reward_threshold = 200.0,
               .render_width = 600,
               .render_height = 400};
  if (continuous) {
    spec.action_dim = 2;
    spec.action_low = {-1.0f, -1.0f};
    spec.action_high = {1.0f, 1.0f};
  }
  return spec;
}

EnvSpec CarRacingSpec(bool continuous) {
  EnvSpec spec{.id = continuous ? "CarRacing-v3" : "CarRacingDiscrete-v3",
               .observation_size = 96 * 96 * 3,
               .num_actions = continuous ? 0 : 5,
               .max_episode_steps = 1000,
               .reward_threshold = 900.0,
               .render_width = 96,
               .render_height = 96};
  if (continuous) {
    spec.action_dim = 3;  // steer, gas, brake
    spec.action_low = {-1.0f, 0.0f, 0.0f};
    spec.action_high = {1.0f, 1.0f, 1.0f};
  }
  return spec;
}

EnvSpec KukaDiverseObjectSpec(bool is_test, int max_steps, int width, int height) {
  // Observation: [step index, step index / max_steps]; the camera image comes from Render.
  return EnvSpec{
      .id = is_test ? "KukaDiverseObjectGraspingTest-v0" : "KukaDiverseObjectGrasping-v0",
      .observation_size = 2,
      .num_actions = 7,
      .max_episode_steps = max_steps,
      .reward_threshold = 0.6,
      .render_width = width,
      .render_height = height};
}

EnvSpec PixelSpec(const EnvSpec& inner, const ImagePipelineConfig& config) {
  config.Validate();
  EnvSpec spec = inner;
  // ceil(inner limit / frame_skip): the outer step that contains the inner limit.
  const int inner_limit = config.time_limit > 0 ? config.time_limit : inner.max_episode_steps;
  spec.max_episode_steps =
      static_cast<int>((int64_t{inner_limit} + config.frame_skip - 1) / config.frame_skip);
  const int raw_width = config.render_width > 0 ? config.render_width : inner.render_width;
  const int raw_height = config.render_height > 0 ? config.render_height : inner.render_height;
  const int64_t cropped_width = int64_t{raw_width} - config.crop_left - config.crop_right;
  const int64_t cropped_height = int64_t{raw_height} - config.crop_top - config.crop_bottom;
  if (cropped_width <= 0 || cropped_height <= 0) {
    throw std::invalid_argument("pixels of " + inner.id + ": the crops leave no pixel of its " +
                                std::to_string(raw_width) + "x" + std::to_string(raw_height) +
                                " frames");
  }
  spec.frame_width = config.width > 0 ? config.width : static_cast<int>(cropped_width);
  spec.frame_height = config.height > 0 ? config.height : static_cast<int>(cropped_height);
  spec.frame_stack = config.stack;
  spec.observation_size = spec.frame_stack * spec.frame_height * spec.frame_width;
  return spec;
}

EnvSpec LookupSpec(const std::string& id) {
  const EnvIdParts parts = ParseEnvId(id);
  if (parts.pixels) return PixelSpec(LookupSpec(parts.base), parts.image);
  struct Entry {
    std::string_view id;
    EnvSpec (*spec)();
  };
  static constexpr std::array kSpecs = {
      Entry{"CartPole-v1", CartPoleSpec},
      Entry{"Catch-v0", CatchSpec},
      Entry{"Pendulum-v1", PendulumSpec},
      Entry{"LunarLander-v3", [] { return LunarLanderSpec(false); }},
      Entry{"LunarLanderContinuous-v3", [] { return LunarLanderSpec(true); }},
      Entry{"CarRacing-v3", [] { return CarRacingSpec(true); }},
      Entry{"CarRacingDiscrete-v3", [] { return CarRacingSpec(false); }},
      Entry{"KukaDiverseObjectGrasping-v0",
            [] { return KukaDiverseObjectSpec(false, 15, 48, 48); }},
      Entry{"KukaDiverseObjectGraspingTest-v0",
            [] { return KukaDiverseObjectSpec(true, 20, 48, 48); }},
  };
  std::string known;
  for (const Entry& e : kSpecs) {
    if (e.id == id) return e.spec();
    known += (known.empty() ? "" : ", ") + std::string(e.id);
  }
  throw std::invalid_argument("unknown environment id \"" + id + "\"; known ids: " + known);
}

}  // namespace rl::envs
