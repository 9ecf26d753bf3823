#include "envs/cartpole.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdio>
#include <stdexcept>
#include <string>

#include "common/check.h"
#include "envs/env_list.h"
#include "envs/raster.h"
#include "envs/render_args.h"
#include "envs/rng.h"
#include "envs/specs.h"

namespace rl::envs {
namespace {

// Drawing geometry of the reference, in pixels of the 600x400 surface before its vertical flip
// (so y grows upwards from the bottom edge).
constexpr double kWorldWidth = CartPole::kXThreshold * 2;
constexpr double kScale = CartPole::kScreenWidth / kWorldWidth;  // 125 px per metre.
constexpr double kPoleWidth = 10.0;
constexpr double kPoleLength = kScale * (2 * CartPole::kLength);  // 125 px.
constexpr double kCartWidth = 50.0;
constexpr double kCartHeight = 30.0;
constexpr double kAxleOffset = kCartHeight / 4.0;  // Axle above the cart's centre line.
constexpr double kCartY = 100;                     // Cart centre line and track height.
constexpr Rgb kPoleColor{202, 152, 101};
constexpr Rgb kAxleColor{129, 132, 203};

}  // namespace

void CartPoleConfig::Validate() const {
  if (!std::isfinite(reset_low) || !std::isfinite(reset_high) || reset_low > reset_high) {
    throw std::invalid_argument(
        "CartPoleConfig: reset_low and reset_high must be finite with reset_low <= reset_high, got "
        "[" +
        std::to_string(reset_low) + ", " + std::to_string(reset_high) + "]");
  }
}

CartPole::CartPole(const CartPoleConfig& config) : SeededEnv(CartPoleSpec()), config_(config) {
  config_.Validate();
}

void CartPole::NewEpisode() {
  for (double& v : state_) v = UniformDouble(rng(), config_.reset_low, config_.reset_high);
  steps_beyond_terminated_.reset();
  UpdateObservation();
}

StepResult CartPole::OnStep(std::span<const float> action) {
  // Accelerations from the equations of motion (same operation order as the reference).
  auto& [x, x_dot, theta, theta_dot] = state_;
  const double force = ActionIndex(action) == 1 ? kForceMag : -kForceMag;
  const double cos_theta = std::cos(theta);
  const double sin_theta = std::sin(theta);
  const double temp = (force + kPoleMassLength * (theta_dot * theta_dot) * sin_theta) / kTotalMass;
  const double theta_acc =
      (kGravity * sin_theta - cos_theta * temp) /
      (kLength * (4.0 / 3.0 - kMassPole * (cos_theta * cos_theta) / kTotalMass));
  const double x_acc = temp - kPoleMassLength * theta_acc * cos_theta / kTotalMass;

  // Integrate over kTau.
  if (config_.integrator == CartPoleIntegrator::kEuler) {
    x = x + kTau * x_dot;
    x_dot = x_dot + kTau * x_acc;
    theta = theta + kTau * theta_dot;
    theta_dot = theta_dot + kTau * theta_acc;
  } else {
    x_dot = x_dot + kTau * x_acc;
    x = x + kTau * x_dot;
    theta_dot = theta_dot + kTau * theta_acc;
    theta = theta + kTau * theta_dot;
  }
  UpdateObservation();

  // Termination (strict comparisons) and reward.
  StepResult result;
  result.terminated = x < -kXThreshold || x > kXThreshold || theta < -kThetaThresholdRadians ||
                      theta > kThetaThresholdRadians;
  if (!result.terminated) {
    result.reward = config_.sutton_barto_reward ? 0.0 : 1.0;
  } else if (!steps_beyond_terminated_.has_value()) {
    // The pole just fell: this step is still rewarded.
    steps_beyond_terminated_ = 0;
    result.reward = config_.sutton_barto_reward ? -1.0 : 1.0;
  } else {
    if (*steps_beyond_terminated_ == 0) {
      std::fprintf(stderr,
                   "WARN: CartPole: Step() called after this episode already returned "
                   "terminated = true. Call Reset() once an episode terminates; further steps "
                   "have undefined meaning.\n");
    }
    ++*steps_beyond_terminated_;
    result.reward = config_.sutton_barto_reward ? -1.0 : 0.0;
  }
  return result;
}

void CartPole::set_state(const std::array<double, 4>& state) {
  state_ = state;
  MarkStarted();
  UpdateObservation();
}

void CartPole::UpdateObservation() {
  for (std::size_t i = 0; i < state_.size(); ++i) observation_[i] = static_cast<float>(state_[i]);
}

void CartPole::Render(std::vector<uint8_t>* rgb, int* width, int* height) const {
  RenderNative(*this, kScreenWidth, kScreenHeight, rgb, width, height);
}

void CartPole::RenderSized(int width, int height, std::vector<uint8_t>* rgb) const {
  CheckRenderArgs(*this, "CartPole", width, height, rgb);

  // The reference draws on a y-up 600x400 surface and flips it; map that surface to the output
  // image (y down), scaling each axis.
  const double sx = width / static_cast<double>(kScreenWidth);
  const double sy = height / static_cast<double>(kScreenHeight);
  const auto to_image = [&](double px, double py) {
    return Point{px * sx, (kScreenHeight - py) * sy};
  };
  Canvas canvas(width, height, rgb);
  canvas.Clear(kWhite);

  // Cart: a kCartWidth x kCartHeight rectangle centred on (cart_x, kCartY). Clamp the centre far
  // outside the screen so that a runaway state cannot overflow the pixel arithmetic.
  const double x = state_[0];
  const double theta = state_[2];
  const double cart_x = std::clamp(x * kScale + kScreenWidth / 2.0, -1e6, 1e6);
  const std::array<Point, 4> cart = {to_image(cart_x - kCartWidth / 2, kCartY - kCartHeight / 2),
                                     to_image(cart_x - kCartWidth / 2, kCartY + kCartHeight / 2),
                                     to_image(cart_x + kCartWidth / 2, kCartY + kCartHeight / 2),
                                     to_image(cart_x + kCartWidth / 2, kCartY - kCartHeight / 2)};
  canvas.FillPolygon(cart, kBlack);

  // Pole: spans [-w/2, length - w/2] along its axis and [-w/2, w/2] across, rotated by -theta
  // about the axle, so a positive theta leans it towards +x.
  const double c = std::cos(theta);
  const double s = std::sin(theta);
  const double left = -kPoleWidth / 2;
  const double right = kPoleWidth / 2;
  const double top = kPoleLength - kPoleWidth / 2;
  const double bottom = -kPoleWidth / 2;
  const auto pole_corner = [&](double px, double py) {
    return to_image(cart_x + px * c + py * s, kCartY + kAxleOffset - px * s + py * c);
  };
  const std::array<Point, 4> pole = {pole_corner(left, bottom), pole_corner(left, top),
                                     pole_corner(right, top), pole_corner(right, bottom)};
  canvas.FillPolygon(pole, kPoleColor);

  // Axle: a circle of radius kPoleWidth / 2 around the pixel (int(cart_x), int(kCartY +
  // kAxleOffset)), with Python's truncating int().
  const double axle_px = std::trunc(cart_x) + 0.5;
  const double axle_py = std::trunc(kCartY + kAxleOffset) + 0.5;
  canvas.FillEllipse(to_image(axle_px, axle_py), kPoleWidth / 2 * sx, kPoleWidth / 2 * sy,
                     kAxleColor);

  // Track: the full-width pixel row at height kCartY, drawn last; at least one row thick.
  const int row_begin = static_cast<int>(std::floor((kScreenHeight - kCartY - 1) * sy + 0.5));
  const int row_end =
      std::max(row_begin + 1, static_cast<int>(std::floor((kScreenHeight - kCartY) * sy + 0.5)));
  canvas.FillPixelRect(0, row_begin, width, row_end, kBlack);
}

// Registered as CartPole-v1 (env_list.inc).
std::unique_ptr<Env> MakeCartPoleV1(const EnvIdParts&) { return std::make_unique<CartPole>(); }

}  // namespace rl::envs
