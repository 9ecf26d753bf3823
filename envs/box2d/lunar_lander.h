// LunarLander: land a rocket on a pad between two flags, with a main engine and two side
// (orientation) engines, on procedurally generated terrain.
//
// Port of Gymnasium's LunarLander-v3 and LunarLanderContinuous-v3:
// https://github.com/Farama-Foundation/Gymnasium/blob/main/gymnasium/envs/box2d/lunar_lander.py
// The physics runs in Box2D 2.4.1 in float, as the reference runs pybox2d (a Box2D 2.3 core) in
// float; the code around it (terrain, engine offsets, observation, reward) runs in double. Box2D
// 2.4 changed the revolute-joint solver and the edge collision code, so trajectories agree with the
// reference statistically, not bit for bit (lunar_lander.cc lists the differences). The time limit
// of 1000 steps is not part of this class: MakeEnv("LunarLander-v3") wraps it in TimeLimit.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <random>
#include <span>
#include <vector>

#include "envs/env.h"
#include "envs/rng.h"

namespace rl::envs {

/// Options of LunarLander: Gymnasium's constructor arguments (render_mode aside), same defaults.
struct LunarLanderConfig {
  bool continuous = false;        // Two continuous actions (main, lateral) instead of 4 discrete.
  double gravity = -10.0;         // World gravity along y, m/s^2; must lie in (-12, 0).
  bool enable_wind = false;       // Wind force and turbulence torque while no leg touches ground.
  double wind_power = 15.0;       // Peak wind force (N); Gymnasium recommends [0, 20].
  double turbulence_power = 1.5;  // Peak turbulence torque (N m); recommended [0, 2].

  /// Throws std::invalid_argument unless gravity lies in the open interval (-12, 0) (the reference
  /// asserts this) and wind_power and turbulence_power are finite. Values outside the recommended
  /// ranges are accepted; the LunarLander constructor prints a warning for them, as the reference
  /// does.
  void Validate() const;
};

/// Pose and velocity of the lander's body as Box2D stores them (float), in world units.
struct LanderKinematics {
  double x = 0;                 // Body origin (not the centre of mass), metres.
  double y = 0;                 // Body origin, metres; the pad is at about 3.3.
  double vx = 0;                // Linear velocity of the centre of mass, m/s.
  double vy = 0;                //
  double angle = 0;             // Radians, counter-clockwise, not wrapped.
  double angular_velocity = 0;  // rad/s, counter-clockwise.
};

/// LunarLander-v3 (discrete) or LunarLanderContinuous-v3 (config.continuous).
///
/// Observation (8 float32, not clipped): [x, y, vx, vy, angle, angular velocity, right leg
/// contact, left leg contact], normalised as in the reference (see NormalisedState).
/// Discrete actions: 0 noop, 1 fire the left orientation engine (turns counter-clockwise and
/// pushes towards -x), 2 fire the main engine, 3 fire the right orientation engine.
/// Continuous action [main, lateral], each clipped to [-1, 1]: the main engine fires when
/// main > 0, at throttle (main + 1) / 2 in [0.5, 1]; a side engine fires when |lateral| > 0.5
/// (lateral < -0.5 the left one, > 0.5 the right one) at throttle |lateral| in (0.5, 1].
///
/// Reward: the difference of the shaping potential (Shaping) between consecutive steps, minus 0.3
/// per step of full main engine and 0.03 per step of full side engine; -100 when the lander's body
/// touches the ground or |x| >= 1, +100 instead when the lander comes to rest (Box2D puts its body
/// to sleep). Each of these ends the episode (terminated); see ApplyTerminationRules.
///
/// Deterministic: the same seed and the same actions give bit-identical trajectories on the same
/// build (each Reset builds a new Box2D world). Not copyable (it owns a Box2D world), movable. Not
/// thread-safe.
class LunarLander : public SeededEnv {
 public:
  // Constants of the reference. Lengths in "pixels" are divided by kScale to get metres.
  static constexpr int kFps = 50;  // Steps per second: the world advances 1/50 s per step.
  static constexpr double kScale = 30.0;
  static constexpr double kMainEnginePower = 13.0;
  static constexpr double kSideEnginePower = 0.6;
  static constexpr double kInitialRandom = 1000.0;  // Bound of each initial force component (N).
  static constexpr double kLegAway = 20;
  static constexpr double kLegDown = 18;
  static constexpr double kLegW = 2;  // Half-extents of the leg boxes.
  static constexpr double kLegH = 8;
  static constexpr double kLegSpringTorque = 40;
  static constexpr double kSideEngineHeight = 14;
  static constexpr double kSideEngineAway = 12;
  static constexpr double kMainEngineYLocation = 4;
  static constexpr int kViewportW = 600;  // Native rendering size in pixels.
  static constexpr int kViewportH = 400;
  static constexpr double kW = kViewportW / kScale;  // World width, 20 m.
  static constexpr double kH = kViewportH / kScale;  // World height, 13.33 m.
  static constexpr int kChunks = 11;                 // Terrain points.
  static constexpr double kHelipadY = kH / 4;
  static constexpr double kHelipadX1 = kW / (kChunks - 1) * 4;  // 8 m.
  static constexpr double kHelipadX2 = kW / (kChunks - 1) * 6;  // 12 m.
  // Box2D solver iterations per step (velocity, position), as the reference passes them.
  static constexpr int kVelocityIterations = 6 * 30;
  static constexpr int kPositionIterations = 2 * 30;

  /// Throws std::invalid_argument if config.Validate() fails.
  explicit LunarLander(const LunarLanderConfig& config = {});
  ~LunarLander() override;
  LunarLander(const LunarLander&) = delete;
  LunarLander& operator=(const LunarLander&) = delete;
  LunarLander(LunarLander&&) noexcept;
  LunarLander& operator=(LunarLander&&) noexcept;

  const LunarLanderConfig& config() const { return config_; }

  // Reset draws, in this order: 12 terrain heights, the 2 components of the initial force, with
  // wind the 2 wind offsets, then the 2 dispersion values of one real physics step with no engine
  // firing (as the reference's reset does); it builds a new Box2D world. Step takes the index
  // (discrete) or [main, lateral] (continuous), draws 2 dispersion values from the RNG every step,
  // and keeps simulating after termination.

  std::span<const float> observation() const override { return observation_; }

  /// 600x400 RGB image like the reference's rgb_array: black sky above the terrain line, white
  /// ground, the lander and its legs in (128, 102, 230) outlined in (77, 77, 128), two white flag
  /// poles with yellow (204, 204, 0) flags at the pad's ends. Exhaust particles are not drawn.
  /// Throws std::logic_error before the first Reset.
  void Render(std::vector<uint8_t>* rgb, int* width, int* height) const override;
  /// Draws the same picture scaled to width x height (geometry scaled per axis).
  void RenderSized(int width, int height, std::vector<uint8_t>* rgb) const override;

  // Introspection, for tests and analysis. All require a Reset (RL_CHECK).

  /// The double-precision state of the last step (or of SetLanderKinematics), from which the
  /// observation (its float32 cast) and the shaping are computed.
  const std::array<double, 8>& state() const { return state_; }
  LanderKinematics lander_kinematics() const;
  /// Whether leg i touches the ground: 0 is the leg on the +x side, 1 the one on the -x side.
  bool leg_ground_contact(int leg) const;
  /// Angle of leg i's revolute joint (leg angle minus lander angle minus the reference angle).
  double leg_joint_angle(int leg) const;
  /// Whether the lander's body has touched the ground this episode.
  bool game_over() const;
  /// Whether Box2D considers the lander awake (false once it has come to rest).
  bool lander_awake() const;
  /// The terrain points: x = 0, 2, ..., 20 and their heights (the pad is points 4..6).
  const std::array<double, kChunks>& terrain_x() const { return chunk_x_; }
  const std::array<double, kChunks>& terrain_y() const { return smooth_y_; }
  /// World-space outlines (metres) of the lander's hull and of legs 0 and 1, in that order: the
  /// Box2D polygons transformed by their bodies' poses.
  std::vector<std::vector<std::array<double, 2>>> body_polygons() const;
  /// The wind and turbulence phase indices (advanced once per step with wind and no contact).
  int64_t wind_index() const { return wind_idx_; }
  int64_t torque_index() const { return torque_idx_; }

  /// Moves the lander to a pose and velocity, carrying the legs along rigidly (their pose relative
  /// to the lander is kept, their velocities follow the rigid motion), wakes the bodies, and
  /// recomputes state() and observation(). The shaping of the new state becomes the reference for
  /// the next step's reward, so that reward reflects that step alone. Contact flags change on the
  /// next Step, when Box2D updates its contacts. Requires a Reset.
  void SetLanderKinematics(const LanderKinematics& kinematics);

  // The reward and observation formulas, exposed for tests.

  /// The normalised state of the reference, in double: [(x - W/2) / (W/2),
  /// (y - (helipad_y + LEG_DOWN/SCALE)) / (H/2), vx (W/2) / FPS, vy (H/2) / FPS, angle,
  /// 20 omega / FPS, leg 0 contact, leg 1 contact].
  static std::array<double, 8> NormalisedState(const LanderKinematics& kinematics,
                                               bool leg0_contact, bool leg1_contact);
  /// The shaping potential: -100 |(s0, s1)| - 100 |(s2, s3)| - 100 |s4| + 10 s6 + 10 s7.
  static double Shaping(const std::array<double, 8>& state);
  /// The end-of-step rules, in the reference's order: a crash (game_over) or |s0| >= 1 sets the
  /// reward to -100 and terminates; then a lander that is not awake sets it to +100 and
  /// terminates (so +100 wins when both hold). Otherwise returns the reward unchanged.
  static StepResult ApplyTerminationRules(double reward, bool game_over, double s0,
                                          bool lander_awake);
  /// Wind force (or turbulence torque) at phase index `index`:
  /// tanh(sin(0.02 index) + sin(pi 0.01 index)) * power.
  static double WindMagnitude(int64_t index, double power);

 private:
  struct Physics;  // The Box2D world, its bodies and the contact listener.

  // Builds a new world and terrain from rng() and takes the reference's initial step.
  void NewEpisode() override;
  // The engines an action fires (discrete or continuous), then StepPhysics.
  StepResult OnStep(std::span<const float> action) override;
  // One step with the sanitised action: the engine throttles and the side direction.
  StepResult StepPhysics(double m_power, double s_power, double direction);
  // Recomputes state_ and observation_ from the bodies and contact flags.
  void UpdateState();
  // Throws std::logic_error unless an episode has started.
  void RequireReset(const char* what) const;

  LunarLanderConfig config_;
  std::unique_ptr<Physics> physics_;  // Null until the first Reset.
  std::array<double, kChunks> chunk_x_{};
  std::array<double, kChunks> smooth_y_{};
  int64_t wind_idx_ = 0;
  int64_t torque_idx_ = 0;
  std::array<double, 8> state_{};
  std::array<float, 8> observation_{};
  double prev_shaping_ = 0;
  bool has_prev_shaping_ = false;  // The reference's prev_shaping is None before the first step.
};

}  // namespace rl::envs
