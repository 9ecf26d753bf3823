#include "envs/pendulum.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "common/check.h"
#include "envs/raster.h"
#include "envs/rng.h"
#include "envs/specs.h"

namespace rl::envs {
namespace {

constexpr Rgb kWhite{255, 255, 255};
constexpr Rgb kRod{204, 77, 77};
constexpr Rgb kBlack{0, 0, 0};
constexpr Rgb kTorque{60, 60, 60};
constexpr double kViewHalfWidth = 2.2;  // world units from the centre to the edge of the view
constexpr double kRodWidth = 0.2;
constexpr double kAxleRadius = 0.05;

}  // namespace

void PendulumConfig::Validate() const {
  if (!std::isfinite(g) || !std::isfinite(x_init) || !std::isfinite(y_init) || x_init < 0 ||
      y_init < 0) {
    throw std::invalid_argument(
        "PendulumConfig: g must be finite and x_init, y_init finite and >= 0");
  }
}

Pendulum::Pendulum(const PendulumConfig& config) : spec_(PendulumSpec()), config_(config) {
  config_.Validate();
}

double Pendulum::AngleNormalize(double x) {
  const double two_pi = 2 * std::numbers::pi;
  double m = std::fmod(x + std::numbers::pi, two_pi);
  if (m < 0) m += two_pi;  // Python's modulo takes the sign of the divisor
  return m - std::numbers::pi;
}

void Pendulum::Reset(uint64_t seed) {
  SeedRng(seed, rng_);
  rng_seeded_ = true;
  Reset();
}

void Pendulum::Reset() {
  if (!rng_seeded_) {
    SeedRngRandomly(rng_);
    rng_seeded_ = true;
  }
  theta_ = UniformDouble(rng_, -config_.x_init, config_.x_init);
  theta_dot_ = UniformDouble(rng_, -config_.y_init, config_.y_init);
  has_state_ = true;
  has_last_u_ = false;
  UpdateObservation();
}

void Pendulum::SetState(double theta, double theta_dot) {
  theta_ = theta;
  theta_dot_ = theta_dot;
  has_state_ = true;
  UpdateObservation();
}

void Pendulum::UpdateObservation() {
  observation_ = {static_cast<float>(std::cos(theta_)), static_cast<float>(std::sin(theta_)),
                  static_cast<float>(theta_dot_)};
}

StepResult Pendulum::Step(int /*action*/) { throw std::logic_error("continuous env"); }

StepResult Pendulum::StepContinuous(std::span<const float> action) {
  if (action.size() != 1) {
    throw std::invalid_argument("Pendulum: expected 1 action value, got " +
                                std::to_string(action.size()));
  }
  if (!std::isfinite(action[0])) throw std::invalid_argument("Pendulum: torque not finite");
  if (!has_state_) throw std::logic_error("Pendulum: call Reset() before Step()");
  const double u = std::clamp(static_cast<double>(action[0]), -kMaxTorque, kMaxTorque);
  const double th = AngleNormalize(theta_);
  const double cost = th * th + 0.1 * theta_dot_ * theta_dot_ + 0.001 * u * u;
  const double g = config_.g;
  double new_theta_dot =
      theta_dot_ +
      (3 * g / (2 * kLength) * std::sin(theta_) + 3.0 / (kMass * kLength * kLength) * u) * kDt;
  new_theta_dot = std::clamp(new_theta_dot, -kMaxSpeed, kMaxSpeed);
  theta_ = theta_ + new_theta_dot * kDt;  // semi-implicit: the new velocity moves the angle
  theta_dot_ = new_theta_dot;
  last_u_ = u;
  has_last_u_ = true;
  UpdateObservation();
  return StepResult{.reward = -cost, .terminated = false, .truncated = false};
}

void Pendulum::Render(std::vector<uint8_t>* rgb, int* width, int* height) const {
  RL_CHECK(width != nullptr && height != nullptr) << "Render needs width and height outputs";
  RenderSized(kScreenSize, kScreenSize, rgb);
  *width = kScreenSize;
  *height = kScreenSize;
}

void Pendulum::RenderSized(int width, int height, std::vector<uint8_t>* rgb) const {
  RL_CHECK(rgb != nullptr) << "RenderSized needs an output buffer";
  if (width <= 0 || height <= 0) {
    throw std::invalid_argument("Pendulum: render size must be positive, got " +
                                std::to_string(width) + "x" + std::to_string(height));
  }
  if (!has_state_) throw std::logic_error("Pendulum: call Reset() before Render()");
  // World (y up, origin at the axle, half-width 2.2) to image (y down), each axis scaled.
  const double sx = width / (2 * kViewHalfWidth);
  const double sy = height / (2 * kViewHalfWidth);
  const auto to_image = [&](double wx, double wy) {
    return Point{(wx + kViewHalfWidth) * sx, (kViewHalfWidth - wy) * sy};
  };
  Canvas canvas(width, height, rgb);
  canvas.Clear(kWhite);

  // The rod, rotated by theta + pi/2 from the +x axis: theta 0 points it straight up.
  const double angle = theta_ + std::numbers::pi / 2;
  const double c = std::cos(angle), s = std::sin(angle);
  const double h = kRodWidth / 2;
  const auto rod_point = [&](double along, double across) {
    return to_image(along * c - across * s, along * s + across * c);
  };
  const std::array<Point, 4> rod = {rod_point(0, -h), rod_point(kLength, -h), rod_point(kLength, h),
                                    rod_point(0, h)};
  canvas.FillPolygon(rod, kRod);
  // Round caps at both ends.
  canvas.FillEllipse(to_image(0, 0), h * sx, h * sy, kRod);
  canvas.FillEllipse(rod_point(kLength, 0), h * sx, h * sy, kRod);

  // The torque: an arc around the axle of |u| / 2 of a half turn, counter-clockwise for u > 0,
  // drawn as a chain of dots with a larger dot at its head.
  if (has_last_u_ && last_u_ != 0) {
    const double radius = 0.5;
    const double sweep = std::numbers::pi * std::abs(last_u_) / kMaxTorque;
    const double start = angle;
    const int dots = std::max(2, static_cast<int>(sweep * 20));
    const double dir = last_u_ > 0 ? 1.0 : -1.0;
    for (int k = 0; k <= dots; ++k) {
      const double a = start + dir * sweep * k / dots;
      const double r = k == dots ? 0.07 : 0.03;
      canvas.FillEllipse(to_image(radius * std::cos(a), radius * std::sin(a)), r * sx, r * sy,
                         kTorque);
    }
  }
  // The axle on top.
  canvas.FillEllipse(to_image(0, 0), kAxleRadius * sx, kAxleRadius * sy, kBlack);
}

}  // namespace rl::envs
