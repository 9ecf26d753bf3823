// CarRacing: drive a car around a procedurally generated track, seen from a 96 x 96 camera that
// follows the car and turns with it.
//
// Port of Gymnasium's CarRacing-v3 (continuous: steer, gas, brake) and of its discrete variant
// (continuous=False, 5 actions), from the behaviour documented in environments.md section 3:
// https://github.com/Farama-Foundation/Gymnasium/blob/main/gymnasium/envs/box2d/car_racing.py
// Track generation (car_racing_track.h) runs in double as the reference does; the car runs in
// Box2D 2.4.1 (float) with the reference's friction-limited tyre model; pictures are drawn by
// car_racing_render.h straight at their output size. car_racing.cc lists where this port differs
// from the reference. The 1,000-frame time limit is not part of this class: MakeEnv wraps it in
// TimeLimit.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "envs/box2d/car_racing_render.h"
#include "envs/box2d/car_racing_track.h"
#include "envs/env.h"
#include "envs/rng.h"

namespace rl::envs {

/// Options of CarRacing: Gymnasium's constructor arguments (render_mode aside), same defaults, plus
/// how pictures are sampled.
struct CarRacingConfig {
  bool continuous = true;              // [steer, gas, brake]; false: Discrete(5).
  bool domain_randomize = false;       // Random road, background and grass colours every Reset.
  double lap_complete_percent = 0.95;  // See CarRacing's class comment on the lap rule.
  // Whether finishing the lap ends the episode (v3); false: the car drives on, as in the TD3
  // article's code (its Gymnasium reported the lap as a truncation, which it ignored), earning
  // -0.1 a frame until the time limit, the off-track rule or the playfield's edge ends it.
  bool lap_ends = true;
  // The TD3 CarRacing article's off-track rule: after every step past the first off_track_after
  // of the episode, the 96 x 96 observation picture is drawn and tested; green above 200 at row
  // 75 and columns 41, 42, 52 and 53 (grass or white kerb on both sides of the car) replaces the
  // step's reward by -10 and ends the episode (terminated). The article starts testing after its
  // 45 no-op frames of zoom-in (MakeEnv sets off_track_after to the id's noop-start).
  bool off_track = false;
  int off_track_after = 0;
  // Frames in a row the car may be off the track before the rule ends the episode (0: the
  // article's rule, at the first). Within them the step's reward is the usual one, so a policy
  // can learn to steer back onto the track, which the article's rule never shows it.
  int off_track_grace = 0;
  // Gas and brake as one pedal (continuous only): actions [steer, pedal] in [-1, 1]^2, a pedal
  // above 0 the gas and below it the brake, so that a policy cannot press both at once. The car,
  // the rewards and the rules are the same; only the action's form changes.
  bool pedals = false;
  // Point samples per pixel side of the 96 x 96 observation (4: 16 samples per pixel, see
  // car_racing_render.h). Larger renders use fewer, never more than one per surface pixel.
  int supersample = 4;

  /// Throws std::invalid_argument unless lap_complete_percent is in [0, 1], supersample in
  /// [1, 8], off_track_after and off_track_grace >= 0, and pedals with continuous actions.
  void Validate() const;
};

/// One wheel of the car, as the tyre model keeps it.
struct CarRacingWheel {
  double gas = 0;  // Rear wheels only: follows the gas control, rising 0.1 per step at most.
  double brake = 0;
  double steer = 0;        // Front wheels only: the target of the steering joint.
  double omega = 0;        // Angular speed, rad/s.
  double phase = 0;        // Integrated omega (drawing only).
  int tiles = 0;           // Road tiles under the wheel: 0 means grass (friction limit 240).
  double joint_angle = 0;  // The revolute joint's angle (wheel angle minus hull angle).
  Vec2d position;          // World position of the wheel's centre.
};

/// The car's pose and motion (Box2D stores them in float).
struct CarRacingCar {
  Vec2d position;    // The hull body's origin.
  double angle = 0;  // Radians; the car faces (-sin angle, cos angle).
  Vec2d velocity;    // Linear velocity of the hull's centre of mass.
  double angular_velocity = 0;
  std::array<CarRacingWheel, 4> wheels{};  // Front left, front right, rear left, rear right.

  double speed() const;  // |velocity|
};

/// CarRacing-v3 (continuous) or "CarRacingDiscrete-v3" (Gymnasium's continuous=False).
///
/// Actions: continuous [steer in [-1, 1] (positive turns right), gas in [0, 1], brake in [0, 1]],
/// clipped to those bounds (the reference clips only gas; the clip changes nothing the car does:
/// the steering joint stops at +-0.4 rad, and a brake of 0.9 or more already locks the wheels).
/// With config.pedals: [steer, pedal], both in [-1, 1]; a pedal p gives gas max(p, 0) and brake
/// max(-p, 0).
/// Discrete: 0 nothing, 1 steer right (-0.6 on the joint's target), 2 steer left (+0.6), 3 gas
/// 0.2, 4 brake 0.8; each sets all three controls.
///
/// Reward: -0.1 per step, +1000/N for each of the N tiles the first time a wheel touches it;
/// exactly -100 on the step the hull leaves the playfield (|x| or |y| above 333.3), which ends the
/// episode (terminated). Visiting every tile ends it too (terminated, lap_finished()) unless
/// config.lap_ends is off; config.off_track adds the TD3 article's rule (see CarRacingConfig).
/// Tiles touched during the reset's own physics step count in the first step's reward, as in the
/// reference.
///
/// Lap rule (Gymnasium issue #1269): the reference ends a lap when tile 0 is touched for the first
/// time after lap_complete_percent of the tiles, but the car starts on tile 0, so that never
/// happens and a lap ends only when every tile has been visited. This port keeps that behaviour,
/// so scores compare with the reference's; lap_complete_percent is honoured as the reference's
/// code is written (it has no effect).
///
/// Observation: the 96 x 96 RGB picture (environments.md 3.10), 27,648 floats in [0, 1]
/// (rows top first, channels interleaved, each byte / 255). It is drawn when observation() or
/// Render() is called, not on every Step (unless the off-track rule tests it), so a pipeline that
/// skips frames skips their drawing; both share one drawing per state.
///
/// Deterministic: the same seed and actions give the same trajectory and pictures on the same
/// build (each Reset builds a new Box2D world). Not copyable, movable, not thread-safe.
class CarRacing : public SeededEnv {
 public:
  static constexpr int kStateSize = 96;  // STATE_W = STATE_H
  static constexpr int kVideoWidth = 600;
  static constexpr int kVideoHeight = 400;
  static constexpr int kFps = 50;
  // Box2D solver iterations per step (velocity, position), as the reference passes them.
  static constexpr int kVelocityIterations = 6 * 30;
  static constexpr int kPositionIterations = 2 * 30;

  /// Throws std::invalid_argument if config.Validate() fails.
  explicit CarRacing(const CarRacingConfig& config = {});
  ~CarRacing() override;
  CarRacing(const CarRacing&) = delete;
  CarRacing& operator=(const CarRacing&) = delete;
  CarRacing(CarRacing&&) noexcept;
  CarRacing& operator=(CarRacing&&) noexcept;

  const CarRacingConfig& config() const { return config_; }

  // Reset: with domain randomisation 7 colour draws, then track attempts of 24 draws each until
  // one succeeds; builds a new world, the track's tiles and the car at node 0, and takes the
  // reference's reset step (physics without an action, t = 0.02). Step: the index (discrete) or
  // [steer, gas, brake] (continuous, clipped).

  /// The 96 x 96 picture as floats (drawn on first use after each Reset or Step).
  std::span<const float> observation() const override;
  /// The 96 x 96 observation picture as bytes (the native size), drawn once per state.
  void Render(std::vector<uint8_t>* rgb, int* width, int* height) const override;
  /// The same picture at any size (600 x 400 for videos), drawn at that size.
  void RenderSized(int width, int height, std::vector<uint8_t>* rgb) const override;

  // Introspection, for tests, controllers and analysis. All require a Reset (std::logic_error).

  const CarRacingTrack& track() const;
  /// The car as Box2D holds it after the last step.
  CarRacingCar car() const;
  /// Tiles visited so far this episode (the reference's tile_visited_count).
  int tiles_visited() const;
  /// Whether tile i has been visited.
  bool tile_visited(int i) const;
  /// The episode's reward so far (the reference's self.reward, the shown score).
  double episode_reward() const;
  /// Whether the last step ended the episode by finishing the lap (v3's info["lap_finished"]).
  bool lap_finished() const { return lap_finished_; }
  /// Seconds simulated since the reset began (0.02 after Reset).
  double time() const { return t_; }
  /// What the next picture shows.
  const CarRacingScene& scene() const;
  /// Samples per pixel side RenderSized uses at width x height: one per surface pixel at most
  /// (ceil of the larger of 1000 / width and 800 / height), at most config().supersample.
  int SupersampleFor(int width, int height) const;

 private:
  struct Physics;  // The Box2D world, the car's bodies and joints, the tile contact listener.

  void NewEpisode() override;
  StepResult OnStep(std::span<const float> action) override;
  // Sets the controls as the reference's Car.steer, Car.gas and Car.brake do.
  void Control(double steer, double gas, double brake);
  // The tyre model, one world step and the clock: what every step does, the reset's included.
  void Advance();
  // The reward and end-of-episode rules of a step taken with an action.
  StepResult Finish();
  // The off-track rule's test on the observation picture (CarRacingConfig::off_track).
  bool OffTrack() const;
  // The 96 x 96 picture of the current state, drawn on first use after each Reset or Step.
  const std::vector<uint8_t>& Picture() const;
  void RequireReset(const char* what) const;
  // Refreshes scene_'s car polygons and indicators from the bodies.
  void UpdateScene() const;

  CarRacingConfig config_;
  CarRacingTrack track_;
  std::unique_ptr<Physics> physics_;  // Null until the first Reset.
  // The reference's colours, as floats (domain randomisation draws them); drawing truncates them.
  std::array<double, 3> road_color_{102, 102, 102};
  std::array<double, 3> background_color_{102, 204, 102};
  std::array<double, 3> grass_color_{102, 230, 102};
  double prev_reward_ = 0;
  double t_ = 0;
  bool lap_finished_ = false;
  int off_track_frames_ = 0;     // frames in a row the off-track rule's test held
  std::vector<int> road_index_;  // Where tile i is in scene_.road.
  mutable CarRacingScene scene_;
  mutable bool scene_stale_ = true;
  mutable std::vector<uint8_t> pixels_;
  mutable bool pixels_stale_ = true;
  mutable std::vector<float> observation_;
  mutable bool observation_stale_ = true;
};

}  // namespace rl::envs
