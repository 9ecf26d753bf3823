// The environment interface shared by the actor and the evaluator: a static spec, Reset, Step, the
// current observation and an RGB rendering. The episode's state (started, steps since Reset) is
// kept by Env itself; time limits live in wrappers such as TimeLimit, as in Gymnasium.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "envs/rng.h"

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
/// == 0) or continuous (num_actions == 0, action_dim > 0). Either way an action is stepped,
/// travels and is stored as action_width() floats: a discrete action is one value holding the
/// index (Env::Step and CheckAction() accept only an integer in range).
struct EnvSpec {
  // Registered id, e.g. "CartPole-v1". "= {}" lets a designated initializer leave it out
  // without a warning (env_list.inc's entries give it apart).
  std::string id = {};
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

/// A discrete action as Step takes it: one float holding the index.
inline std::array<float, 1> DiscreteAction(int index) { return {static_cast<float>(index)}; }

/// One environment instance, and the state of its episode (started or not, steps since Reset),
/// kept here once for every env and wrapper. Reset and Step are not virtual: they check the
/// action and the episode, keep the step count, and call the env's OnReset and OnStep. Not
/// thread-safe: an instance is used by one thread at a time.
class Env {
 public:
  virtual ~Env() = default;

  /// Static spec; the reference stays valid for the lifetime of the env.
  const EnvSpec& spec() const { return spec_; }

  /// Starts an episode with the env's own RNG seeded from `seed` (each instance owns its RNG, so
  /// instances never share random state).
  void Reset(uint64_t seed) { StartEpisode(seed); }

  /// Starts an episode continuing the env's RNG stream (like Gymnasium's reset() without a seed
  /// after a seeded one). Before any seeded Reset, the RNG is seeded from std::random_device.
  void Reset() { StartEpisode(std::nullopt); }

  /// Advances one step with an action of spec().action_width() floats: a discrete action is one
  /// value holding the index (DiscreteAction), a continuous one action_dim values that the env
  /// clips to [action_low, action_high] (infinities included). Throws std::invalid_argument with
  /// CheckAction()'s reason for a bad width, a NaN, or a discrete value that is not an integer in
  /// [0, num_actions); then std::logic_error if Reset was never called. A step that throws is not
  /// counted. O(action width) on top of the env's own step.
  StepResult Step(std::span<const float> action);

  /// Steps taken since the last Reset (during OnStep: including the step being taken).
  int64_t elapsed_steps() const { return elapsed_steps_; }
  /// Whether an episode has started (Reset, or a state set by a test hook).
  bool started() const { return started_; }

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
  explicit Env(EnvSpec spec) : spec_(std::move(spec)) {}
  // Copying and moving are for derived classes only, so that an Env is never sliced.
  Env(const Env&) = default;
  Env& operator=(const Env&) = default;
  Env(Env&&) = default;
  Env& operator=(Env&&) = default;

  /// Starts an episode: `seed` is Reset(seed)'s, or empty for Reset().
  virtual void OnReset(std::optional<uint64_t> seed) = 0;
  /// One step with an action Step has checked (width, finite, a discrete index in range); runs
  /// after an episode started, with elapsed_steps() already counting this step.
  virtual StepResult OnStep(std::span<const float> action) = 0;

  /// For wrappers that change their inner env's spec, in their constructor.
  EnvSpec& mutable_spec() { return spec_; }
  /// For test hooks that set a state: counts as a Reset for Step's precondition (the step count
  /// is left alone).
  void MarkStarted() { started_ = true; }
  /// The index held by a checked discrete action.
  static int ActionIndex(std::span<const float> action) { return static_cast<int>(action[0]); }

 private:
  void StartEpisode(std::optional<uint64_t> seed);

  EnvSpec spec_;
  bool started_ = false;
  int64_t elapsed_steps_ = 0;
};

/// An env that draws its episodes from an RNG of its own (std::mt19937_64 seeded as envs/rng.h
/// says): Reset(seed) seeds it, Reset() continues its stream (seeded from std::random_device if
/// it never was), and both then call NewEpisode. Copies continue the same stream.
class SeededEnv : public Env {
 protected:
  using Env::Env;
  /// Draws a new initial state from rng().
  virtual void NewEpisode() = 0;
  EnvRng& rng() { return rng_; }

 private:
  void OnReset(std::optional<uint64_t> seed) final;

  EnvRng rng_;
};

}  // namespace rl::envs
