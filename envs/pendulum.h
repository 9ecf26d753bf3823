// Pendulum: swing a pendulum up from any angle and hold it upright with a limited torque.
//
// Port of Gymnasium's Pendulum-v1 (environments.md section 4b), the usual first check of a
// continuous-control learner. Internal state (theta, theta_dot) is double; theta 0 is upright,
// positive counter-clockwise. The observation is [cos(theta), sin(theta), theta_dot] as float32.
// The 200-step time limit is not part of this class: MakeEnv("Pendulum-v1") wraps it in TimeLimit.
#pragma once

#include <array>
#include <cstdint>
#include <numbers>
#include <random>
#include <span>
#include <vector>

#include "envs/env.h"

namespace rl::envs {

/// Options of Pendulum; the defaults are Gymnasium's.
struct PendulumConfig {
  double g = 10.0;                   // gravity (the constructor argument of the reference)
  double x_init = std::numbers::pi;  // theta starts uniform in [-x_init, x_init]
  double y_init = 1.0;               // theta_dot starts uniform in [-y_init, y_init]

  /// Throws std::invalid_argument unless g is finite and both bounds are finite and >= 0.
  void Validate() const;
};

/// Pendulum-v1. One continuous action, the torque, clipped to [-2, 2]. The reward of a step is
/// -(angle_normalize(theta)^2 + 0.1 theta_dot^2 + 0.001 u^2) of the state before the step; the
/// episode never terminates. Copyable. Not thread-safe.
class Pendulum : public Env {
 public:
  static constexpr double kMaxSpeed = 8.0;
  static constexpr double kMaxTorque = 2.0;
  static constexpr double kDt = 0.05;
  static constexpr double kMass = 1.0;
  static constexpr double kLength = 1.0;
  // Native rendering size in pixels.
  static constexpr int kScreenSize = 500;

  /// Throws std::invalid_argument if config.Validate() fails.
  explicit Pendulum(const PendulumConfig& config = {});

  const EnvSpec& spec() const override { return spec_; }

  /// Seeds the RNG (as every env: envs/rng.h) and draws theta, then theta_dot.
  void Reset(uint64_t seed) override;
  void Reset() override;

  /// Discrete steps are refused: std::logic_error("continuous env").
  StepResult Step(int action) override;
  /// One step with the torque action[0] (clipped to [-2, 2]). Throws std::invalid_argument for an
  /// action of another size or a non-finite torque, std::logic_error before the first Reset.
  StepResult StepContinuous(std::span<const float> action) override;

  std::span<const float> observation() const override { return observation_; }

  /// 500 x 500 RGB like the reference: white background, a rod of length 1 and width 0.2 (view
  /// half-width 2.2) in (204, 77, 77) with round caps, a black axle, and the last torque shown as
  /// an arc around the axle, its length proportional to |u| and its head in the torque's
  /// direction (the reference draws an arrow image scaled by |u|).
  void Render(std::vector<uint8_t>* rgb, int* width, int* height) const override;
  /// The same drawing at any size (drawn at that size, not resampled).
  void RenderSized(int width, int height, std::vector<uint8_t>* rgb) const override;

  /// Sets the state (for tests and replays of recorded states).
  void SetState(double theta, double theta_dot);
  double theta() const { return theta_; }
  double theta_dot() const { return theta_dot_; }
  /// ((x + pi) mod 2 pi) - pi with Python's modulo (the result of mod is in [0, 2 pi)).
  static double AngleNormalize(double x);

 private:
  void UpdateObservation();

  EnvSpec spec_;
  PendulumConfig config_;
  std::mt19937_64 rng_;
  bool rng_seeded_ = false;
  bool has_state_ = false;
  double theta_ = 0;
  double theta_dot_ = 0;
  double last_u_ = 0;
  bool has_last_u_ = false;
  std::array<float, 3> observation_{};
};

}  // namespace rl::envs
