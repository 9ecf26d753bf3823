// Pendulum: swing a pendulum up from any angle and hold it upright with a limited torque.
//
// Port of Gymnasium's Pendulum-v1 (environments.md section 4b), the usual first check of a
// continuous-control learner:
// https://github.com/Farama-Foundation/Gymnasium/blob/main/gymnasium/envs/classic_control/pendulum.py
// Internal state (theta, theta_dot) is double; theta 0 is upright, positive counter-clockwise. The
// observation is [cos(theta), sin(theta), theta_dot] cast to float32. The 200-step time limit is
// not part of this class: MakeEnv("Pendulum-v1") wraps it in TimeLimit.
#pragma once

#include <array>
#include <cstdint>
#include <numbers>
#include <optional>
#include <random>
#include <span>
#include <vector>

#include "envs/env.h"
#include "envs/rng.h"

namespace rl::envs {

/// Options of Pendulum. The defaults are those of Gymnasium's Pendulum-v1.
struct PendulumConfig {
  double g = 10.0;                   // Gravity (m/s^2), the reference's constructor argument.
  double x_init = std::numbers::pi;  // theta starts uniform in [-x_init, x_init) (reset option).
  double y_init = 1.0;  // theta_dot starts uniform in [-y_init, y_init) (reset option).

  /// Throws std::invalid_argument unless g is finite and x_init, y_init are finite and >= 0.
  void Validate() const;
};

/// Pendulum-v1. One continuous action, the torque u (N m), clipped to [-2, 2]. A step computes,
/// from the state before it, cost = angle_normalize(theta)^2 + 0.1 theta_dot^2 + 0.001 u^2, then
/// theta_dot += (3 g / (2 l) sin(theta) + 3 / (m l^2) u) dt clipped to [-8, 8], then theta +=
/// theta_dot dt with the new velocity (semi-implicit), and returns reward -cost, which lies in
/// [-16.2736044, 0]. theta itself is never wrapped. The episode never terminates or truncates.
/// Copyable (the copy continues the same RNG stream). Not thread-safe.
class Pendulum : public SeededEnv {
 public:
  // Physical constants (SI units), as in the reference.
  static constexpr double kMaxSpeed = 8.0;   // rad/s
  static constexpr double kMaxTorque = 2.0;  // N m
  static constexpr double kDt = 0.05;        // Seconds per step.
  static constexpr double kMass = 1.0;       // kg
  static constexpr double kLength = 1.0;     // m
  // Native rendering size in pixels.
  static constexpr int kScreenSize = 500;

  /// Throws std::invalid_argument if config.Validate() fails.
  explicit Pendulum(const PendulumConfig& config = {});

  const PendulumConfig& config() const { return config_; }

  // Spec: PendulumSpec() (envs/specs.h): id "Pendulum-v1", observation_size 3, action_dim 1 in
  // [-2, 2]. Reset draws theta, then theta_dot, each with one UniformDouble, and forgets the last
  // torque. Step takes the torque action[0], clipped to [-2, 2] (so an infinite torque is the
  // bound); SetState also counts as a Reset for its precondition.

  std::span<const float> observation() const override { return observation_; }

  /// 500 x 500 RGB like the reference's rgb_array: white background; a rod of length 1 and width
  /// 0.2 (the view spans [-2.2, 2.2] world units) in (204, 77, 77) from the axle in the direction
  /// theta + pi/2, with round caps; the last torque as a dark grey circular arrow around the axle,
  /// its size proportional to |u| (1 world unit across at |u| = 2), counter-clockwise for u > 0
  /// and clockwise for u < 0 (the reference blits an arrow image; this one is drawn); a black
  /// axle of radius 0.05 on top. y is up. Throws std::logic_error before the first Reset.
  void Render(std::vector<uint8_t>* rgb, int* width, int* height) const override;
  /// Draws the same picture directly at width x height (geometry scaled per axis, not resampled).
  /// Throws std::invalid_argument for a non-positive size, std::logic_error before the first Reset.
  void RenderSized(int width, int height, std::vector<uint8_t>* rgb) const override;

  /// Overwrites the physical state (and the observation), for tests and analysis. Leaves the last
  /// torque unchanged; counts as a Reset for the Step precondition.
  void SetState(double theta, double theta_dot);
  /// theta (rad, not wrapped) and theta_dot (rad/s).
  double theta() const { return theta_; }
  double theta_dot() const { return theta_dot_; }
  /// The clipped torque of the last step, or nothing since the last Reset (shown by Render).
  std::optional<double> last_u() const { return last_u_; }

  /// ((x + pi) mod 2 pi) - pi with Python's modulo (the remainder takes the divisor's sign), so
  /// the result is in [-pi, pi): pi maps to -pi.
  static double AngleNormalize(double x);

 private:
  void NewEpisode() override;
  StepResult OnStep(std::span<const float> action) override;
  // Refreshes observation_ from theta_ and theta_dot_.
  void UpdateObservation();

  PendulumConfig config_;
  double theta_ = 0;
  double theta_dot_ = 0;
  std::optional<double> last_u_;
  std::array<float, 3> observation_{};
};

}  // namespace rl::envs
