#include "envs/pendulum.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
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

// Drawing geometry of the reference, in pixels of its 500 x 500 surface before the vertical flip
// (so y grows upwards from the bottom edge and angles turn counter-clockwise).
constexpr double kSurface = Pendulum::kScreenSize;
constexpr double kBound = 2.2;                      // World units from the axle to each edge.
constexpr double kScale = kSurface / (kBound * 2);  // 113.6 px per world unit.
constexpr int kAxle = Pendulum::kScreenSize / 2;    // The axle's pixel (integer, as `// 2`).
constexpr double kOffset = kAxle;
constexpr double kRodLength = 1 * kScale;
constexpr double kRodWidth = 0.2 * kScale;
// Circle radii truncated by int() as in the reference: 11 px for the caps, 5 px for the axle.
constexpr double kCapRadius = static_cast<int>(kRodWidth / 2);
constexpr double kAxleRadius = static_cast<int>(0.05 * kScale);
// The torque arrow, in fractions of the side of its square (kScale * |u| / 2 px): a ring of
// three quarters of a turn and a triangular head at its end.
constexpr double kArrowInner = 0.28;
constexpr double kArrowOuter = 0.38;
constexpr double kArrowHeadHalfWidth = 0.15;  // Across the ring, from its centre line.
constexpr double kArrowHeadLength = 0.2;      // Along the tangent.
constexpr double kArrowSweep = 1.5 * std::numbers::pi;
constexpr int kArrowSegments = 48;
constexpr Rgb kRodColor{204, 77, 77};
constexpr Rgb kArrowColor{64, 64, 64};

}  // namespace

void PendulumConfig::Validate() const {
  if (!std::isfinite(g) || !std::isfinite(x_init) || !std::isfinite(y_init) || x_init < 0 ||
      y_init < 0) {
    throw std::invalid_argument(
        "PendulumConfig: g must be finite and x_init, y_init finite and >= 0, got g = " +
        std::to_string(g) + ", x_init = " + std::to_string(x_init) +
        ", y_init = " + std::to_string(y_init));
  }
}

Pendulum::Pendulum(const PendulumConfig& config) : SeededEnv(PendulumSpec()), config_(config) {
  config_.Validate();
}

double Pendulum::AngleNormalize(double x) {
  // CPython's float modulo: fmod, then move a remainder of the wrong sign by one divisor.
  constexpr double kTwoPi = 2 * std::numbers::pi;
  double m = std::fmod(x + std::numbers::pi, kTwoPi);
  if (m < 0) m += kTwoPi;
  return m - std::numbers::pi;
}

void Pendulum::NewEpisode() {
  // The reference draws both with one uniform(low=-high, high=high): theta first.
  theta_ = UniformDouble(rng(), -config_.x_init, config_.x_init);
  theta_dot_ = UniformDouble(rng(), -config_.y_init, config_.y_init);
  last_u_.reset();
  UpdateObservation();
}

void Pendulum::SetState(double theta, double theta_dot) {
  theta_ = theta;
  theta_dot_ = theta_dot;
  MarkStarted();
  UpdateObservation();
}

void Pendulum::UpdateObservation() {
  observation_ = {static_cast<float>(std::cos(theta_)), static_cast<float>(std::sin(theta_)),
                  static_cast<float>(theta_dot_)};
}

StepResult Pendulum::OnStep(std::span<const float> action) {
  // Clip the torque, then the cost of the state before the step.
  const double u = std::clamp(static_cast<double>(action[0]), -kMaxTorque, kMaxTorque);
  const double th = theta_;
  const double thdot = theta_dot_;
  const double th_normalized = AngleNormalize(th);
  const double cost = th_normalized * th_normalized + 0.1 * (thdot * thdot) + 0.001 * (u * u);

  // Semi-implicit Euler: the clipped new velocity moves the angle (reference operation order).
  const double g = config_.g;
  double new_thdot =
      thdot +
      (3 * g / (2 * kLength) * std::sin(th) + 3.0 / (kMass * (kLength * kLength)) * u) * kDt;
  new_thdot = std::clamp(new_thdot, -kMaxSpeed, kMaxSpeed);
  theta_ = th + new_thdot * kDt;
  theta_dot_ = new_thdot;
  last_u_ = u;
  UpdateObservation();
  return StepResult{.reward = -cost, .terminated = false, .truncated = false};
}

void Pendulum::Render(std::vector<uint8_t>* rgb, int* width, int* height) const {
  RenderNative(*this, kScreenSize, kScreenSize, rgb, width, height);
}

void Pendulum::RenderSized(int width, int height, std::vector<uint8_t>* rgb) const {
  CheckRenderArgs(*this, "Pendulum", width, height, rgb);

  // The reference draws on a 500 x 500 surface and flips it vertically; map that surface (taken
  // as y up) to the output image (y down), scaling each axis. Its shapes have integer pixel
  // coordinates, and pixel p is painted when p lies inside: here its centre p + 0.5 does.
  const double sx = width / kSurface;
  const double sy = height / kSurface;
  const auto to_image = [&](double px, double py) { return Point{px * sx, (kSurface - py) * sy}; };
  const auto pixel_centre = [&](double px, double py) {
    return to_image(std::floor(px) + 0.5, std::floor(py) + 0.5);
  };
  Canvas canvas(width, height, rgb);
  canvas.Clear(kWhite);

  // Rod: spans [0, length] along its axis and [-width/2, width/2] across, rotated by
  // theta + pi/2 about the axle, so theta 0 points it up and theta pi/2 to the left.
  const double angle = theta_ + std::numbers::pi / 2;
  const double c = std::cos(angle);
  const double s = std::sin(angle);
  const auto rotated = [&](double along, double across) {
    return std::array<double, 2>{along * c - across * s + kOffset,
                                 along * s + across * c + kOffset};
  };
  std::array<Point, 4> rod;
  const std::array<std::array<double, 2>, 4> corners = {{{0, -kRodWidth / 2},
                                                         {0, kRodWidth / 2},
                                                         {kRodLength, kRodWidth / 2},
                                                         {kRodLength, -kRodWidth / 2}}};
  for (std::size_t i = 0; i < corners.size(); ++i) {
    const auto [px, py] = rotated(corners[i][0], corners[i][1]);
    rod[i] = pixel_centre(px, py);
  }
  canvas.FillPolygon(rod, kRodColor);

  // Round caps: discs at the axle and at the rod's end (its pixel truncated, as int() does).
  canvas.FillEllipse(pixel_centre(kOffset, kOffset), kCapRadius * sx, kCapRadius * sy, kRodColor);
  const auto [end_x, end_y] = rotated(kRodLength, 0);
  canvas.FillEllipse(pixel_centre(end_x, end_y), kCapRadius * sx, kCapRadius * sy, kRodColor);

  // Torque: a circular arrow over the rod, centred on the axle, in a square of side
  // kScale * |u| / 2 px. Clockwise for u < 0 from the upper right round to the upper left;
  // mirrored left-right (counter-clockwise) for u > 0. Nothing for u == 0, as the reference's
  // arrow image then has no pixels.
  if (last_u_.has_value() && *last_u_ != 0) {
    const double side = kScale * std::abs(*last_u_) / 2;
    const double dir = *last_u_ > 0 ? 1.0 : -1.0;
    const double start = std::numbers::pi / 2 + dir * std::numbers::pi / 4;
    const double cx = kOffset + 0.5;
    const double cy = kOffset + 0.5;
    const auto polar = [&](double radius, double a) {
      return to_image(cx + radius * side * std::cos(a), cy + radius * side * std::sin(a));
    };
    // The ring: out along its outer edge, back along its inner edge.
    std::array<Point, 2 * (kArrowSegments + 1)> ring;
    for (int k = 0; k <= kArrowSegments; ++k) {
      const double a = start + dir * kArrowSweep * k / kArrowSegments;
      ring[static_cast<std::size_t>(k)] = polar(kArrowOuter, a);
      ring[ring.size() - 1 - static_cast<std::size_t>(k)] = polar(kArrowInner, a);
    }
    canvas.FillPolygon(ring, kArrowColor);
    // The head: a triangle across the ring's end, its tip ahead along the tangent.
    const double end = start + dir * kArrowSweep;
    const double mid = (kArrowInner + kArrowOuter) / 2;
    const double tip_x = cx + side * (mid * std::cos(end) - dir * kArrowHeadLength * std::sin(end));
    const double tip_y = cy + side * (mid * std::sin(end) + dir * kArrowHeadLength * std::cos(end));
    const std::array<Point, 3> head = {polar(mid - kArrowHeadHalfWidth, end),
                                       polar(mid + kArrowHeadHalfWidth, end),
                                       to_image(tip_x, tip_y)};
    canvas.FillPolygon(head, kArrowColor);
  }

  // Axle: a black disc drawn last.
  canvas.FillEllipse(pixel_centre(kOffset, kOffset), kAxleRadius * sx, kAxleRadius * sy, kBlack);
}

// Registered as Pendulum-v1 (env_list.inc).
std::unique_ptr<Env> MakePendulumV1(const EnvIdParts&) { return std::make_unique<Pendulum>(); }

}  // namespace rl::envs
