// The environment interface shared by the actor and the evaluator: a static spec, Reset, Step, the
// current observation and an RGB rendering. Episode bookkeeping (time limits) lives in wrappers
// such as TimeLimit, as in Gymnasium.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace rl::envs {

/// Outcome of one Step. `terminated` means the MDP reached a terminal state (no bootstrapping);
/// `truncated` means the episode was cut short (by a time limit); both can be true at once.
struct StepResult {
  double reward = 0;
  bool terminated = false;
  bool truncated = false;
};

/// Static description of an environment (shapes and registration data), known without building
/// the env (LookupSpec in envs/specs.h). An env is either discrete (num_actions > 0, action_dim
/// == 0; use Step) or continuous (num_actions == 0, action_dim > 0; use StepContinuous). Either
/// way an action travels and is stored as action_width() floats: a discrete action is one value
/// holding the index (Act() and CheckAction() accept only an integer in range).
struct EnvSpec {
  std::string id;               // Registered id, e.g. "CartPole-v1".
  int observation_size = 0;     // Number of float32 values in observation().
  int num_actions = 0;          // Discrete actions are 0 .. num_actions - 1; 0 for continuous envs.
  int max_episode_steps = 0;    // Time limit applied by the registry (TimeLimit).
  double reward_threshold = 0;  // Average return at which the task counts as solved.
  int action_dim = 0;           // Size of a continuous action vector; 0 for discrete envs.
  // Bounds of each component of a continuous action (action_dim values each, a box); the env
  // clips values outside them. Empty for discrete envs.
  std::vector<float> action_low = {};
  std::vector<float> action_high = {};
  // Pixel envs (frame_stack > 0): observation() is the stack of the last frame_stack grayscale
  // frames of frame_height x frame_width pixels, oldest first, each pixel divided by 255, so
  // observation_size == frame_stack * frame_height * frame_width; frame() is the newest frame as
  // bytes. After a reset the stack holds the first frame frame_stack times (never frames of the
  // previous episode). All three are 0 for envs with flat observations.
  int frame_height = 0;
  int frame_width = 0;
  int frame_stack = 0;
  // Size of Render()'s image (the native size), so that a pixel pipeline's frame size is known
  // without rendering.
  int render_width = 0;
  int render_height = 0;

  bool continuous() const { return num_actions == 0; }
  /// Floats per action: action_dim for a continuous env, 1 (the index) for a discrete one.
  int action_width() const { return continuous() ? action_dim : 1; }
};

/// Why `action` is not a valid action of `spec`, or nullptr: a width other than action_width(),
/// a value that is not finite, a discrete value that is not an integer in [0, num_actions), or a
/// continuous value outside [action_low, action_high] widened by `tolerance` on each side.
/// O(width); no allocation.
const char* CheckAction(const EnvSpec& spec, std::span<const float> action, float tolerance = 0);

/// One environment instance. Not thread-safe: an instance is used by one thread at a time. Each
/// instance owns its RNG, so instances never share random state.
class Env {
 public:
  virtual ~Env() = default;

  /// Static spec; the reference stays valid for the lifetime of the env.
  virtual const EnvSpec& spec() const = 0;

  /// Seeds the env's own RNG from `seed` and samples an initial state.
  virtual void Reset(uint64_t seed) = 0;

  /// Samples an initial state, continuing the env's RNG stream (like Gymnasium's reset() without a
  /// seed after a seeded one). Before any seeded Reset, the RNG is seeded from std::random_device.
  virtual void Reset() = 0;

  /// Advances one step of a discrete env. Throws std::invalid_argument for an action outside
  /// [0, num_actions), and std::logic_error if Reset was never called or the env is continuous.
  virtual StepResult Step(int action) = 0;

  /// Advances one step of a continuous env with an action of spec().action_dim floats. Throws
  /// std::invalid_argument for an action of the wrong size, std::logic_error if Reset was never
  /// called. The default (for discrete envs) throws std::logic_error("discrete env").
  virtual StepResult StepContinuous(std::span<const float> action);

  /// Steps with an action in the one representation (EnvSpec::action_width() floats): Step() with
  /// the index for a discrete env, StepContinuous() for a continuous one. Throws
  /// std::invalid_argument with CheckAction()'s reason for a bad action (bounds are not checked
  /// here: a continuous env clips).
  StepResult Act(std::span<const float> action);

  /// Current observation (observation_size float32 values). Valid until the next Reset or Step.
  virtual std::span<const float> observation() const = 0;

  /// Pixel envs only: the newest grayscale frame, frame_height x frame_width bytes, row-major
  /// (the last frame of the stack in observation(), before the division by 255). Valid until the
  /// next Reset or Step. The default (for flat envs) throws std::logic_error("not a pixel env").
  virtual std::span<const uint8_t> frame() const;

  /// Renders the current state at the env's native size as RGB bytes, row-major, top row first,
  /// height x width x 3. Resizes *rgb and writes the size to *width and *height.
  virtual void Render(std::vector<uint8_t>* rgb, int* width, int* height) const = 0;

  /// Renders at width x height (both positive, else std::invalid_argument); same layout as Render.
  /// The default renders at the native size and resamples by area averaging; envs that can draw
  /// at any size override it.
  virtual void RenderSized(int width, int height, std::vector<uint8_t>* rgb) const;

 protected:
  // Copying and moving are for derived classes only, so that an Env is never sliced.
  Env() = default;
  Env(const Env&) = default;
  Env& operator=(const Env&) = default;
  Env(Env&&) = default;
  Env& operator=(Env&&) = default;
};

}  // namespace rl::envs
