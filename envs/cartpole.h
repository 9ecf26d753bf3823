// CartPole: a pole hinged on a cart that moves along a frictionless track; push the cart left or
// right to keep the pole upright.
//
// Port of Gymnasium's CartPole-v1 (classic dynamics of Barto, Sutton and Anderson, 1983):
// https://github.com/Farama-Foundation/Gymnasium/blob/main/gymnasium/envs/classic_control/cartpole.py
// Internal state is double, the observation is that state cast to float32. The time limit of 500
// steps is not part of this class: MakeEnv("CartPole-v1") wraps it in TimeLimit.
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

/// How CartPole integrates its equations of motion over one step of kTau seconds.
enum class CartPoleIntegrator {
  kEuler,              // Gymnasium's default "euler": positions use the old velocities.
  kSemiImplicitEuler,  // Any other string in Gymnasium: velocities first, positions use the new.
};

/// Options of CartPole. The defaults are those of Gymnasium's CartPole-v1.
struct CartPoleConfig {
  CartPoleIntegrator integrator = CartPoleIntegrator::kEuler;
  double reset_low = -0.05;  // Each state component starts uniform in [reset_low, reset_high).
  double reset_high = 0.05;  // Gymnasium's reset(options={"low": ..., "high": ...}).
  bool sutton_barto_reward = false;  // Rewards 0 alive and -1 on and after termination.

  /// Throws std::invalid_argument unless both bounds are finite and reset_low <= reset_high.
  void Validate() const;
};

/// CartPole-v1. State and observation are [x, x_dot, theta, theta_dot] (m, m/s, rad, rad/s); theta
/// is 0 upright and positive when the pole leans towards +x. Action 0 pushes the cart left, 1
/// right. Copyable (the copy continues the same RNG stream). Not thread-safe.
class CartPole : public SeededEnv {
 public:
  // Physical constants (SI units), as in the reference.
  static constexpr double kGravity = 9.8;
  static constexpr double kMassCart = 1.0;
  static constexpr double kMassPole = 0.1;
  static constexpr double kTotalMass = kMassPole + kMassCart;
  static constexpr double kLength = 0.5;  // Half the pole's length.
  static constexpr double kPoleMassLength = kMassPole * kLength;
  static constexpr double kForceMag = 10.0;
  static constexpr double kTau = 0.02;  // Seconds per step.
  // Episode ends when |theta| > 12 degrees or |x| > 2.4 (strict comparisons).
  static constexpr double kThetaThresholdRadians = 12 * 2 * std::numbers::pi / 360;
  static constexpr double kXThreshold = 2.4;
  // Native rendering size in pixels.
  static constexpr int kScreenWidth = 600;
  static constexpr int kScreenHeight = 400;

  /// Throws std::invalid_argument if config.Validate() fails.
  explicit CartPole(const CartPoleConfig& config = {});

  const CartPoleConfig& config() const { return config_; }

  // Reset draws x, x_dot, theta, theta_dot in that order, each uniform in [reset_low,
  // reset_high). Step: one step of the dynamics. Reward is 1 while not terminated and on the
  // step that terminates; stepping again after termination keeps integrating, returns 0 and
  // prints a warning to stderr once per episode. truncated is always false (see TimeLimit).

  std::span<const float> observation() const override { return observation_; }

  /// 600x400 RGB image like the reference's rgb_array: white background, black track and cart,
  /// brown pole, blue-grey axle. Throws std::logic_error before the first Reset.
  void Render(std::vector<uint8_t>* rgb, int* width, int* height) const override;
  /// Draws the same picture scaled to width x height (geometry scaled per axis).
  void RenderSized(int width, int height, std::vector<uint8_t>* rgb) const override;

  /// Physical state [x, x_dot, theta, theta_dot] in double.
  const std::array<double, 4>& state() const { return state_; }
  /// Overwrites the physical state (and the observation), for tests and analysis. Leaves the
  /// termination bookkeeping of the episode unchanged; counts as a Reset for the Step precondition.
  void set_state(const std::array<double, 4>& state);

 private:
  void NewEpisode() override;
  StepResult OnStep(std::span<const float> action) override;
  // Refreshes observation_ from state_.
  void UpdateObservation();

  CartPoleConfig config_;
  std::array<double, 4> state_{};
  std::array<float, 4> observation_{};
  // Steps taken since the episode first reported terminated; empty until then (as in the
  // reference, where it is None).
  std::optional<int64_t> steps_beyond_terminated_;
};

}  // namespace rl::envs
