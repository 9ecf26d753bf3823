#include "envs/kuka/kuka_objects.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <random>
#include <stdexcept>
#include <string>

#include "envs/rng.h"

namespace rl::envs::kuka {
namespace {

using Points = std::vector<Eigen::Vector3d>;
constexpr double kPi = std::numbers::pi;

// A point uniform on the unit sphere.
Eigen::Vector3d OnSphere(std::mt19937_64& rng) {
  const double z = UniformDouble(rng, -1, 1);
  const double a = UniformDouble(rng, 0, 2 * kPi);
  const double r = std::sqrt(std::max(0.0, 1 - z * z));
  return {r * std::cos(a), r * std::sin(a), z};
}

// The six ends of the semi-axes of an ellipsoid around `centre` (so that the hull spans the
// ellipsoid's full extent along each axis).
Points AxisEnds(const Eigen::Vector3d& centre, const Eigen::Vector3d& radii) {
  Points p;
  for (int k = 0; k < 3; ++k) {
    for (double s : {-1.0, 1.0}) {
      Eigen::Vector3d v = centre;
      v[k] += s * radii[k];
      p.push_back(v);
    }
  }
  return p;
}

// The axis ends plus `n` random points on an ellipsoid with semi-axes `radii` around `centre`.
Points Lump(std::mt19937_64& rng, int n, const Eigen::Vector3d& centre,
            const Eigen::Vector3d& radii) {
  Points p = AxisEnds(centre, radii);
  for (int i = 0; i < n; ++i) p.push_back(centre + OnSphere(rng).cwiseProduct(radii));
  return p;
}

// The corners of a box with half extents `h` around `centre`, each moved by up to `jitter`.
Points BoxCorners(std::mt19937_64& rng, const Eigen::Vector3d& centre, const Eigen::Vector3d& h,
                  double jitter) {
  Points p;
  for (int i = 0; i < 8; ++i) {
    const Eigen::Vector3d corner(i & 1 ? h.x() : -h.x(), i & 2 ? h.y() : -h.y(),
                                 i & 4 ? h.z() : -h.z());
    const Eigen::Vector3d d(UniformDouble(rng, -jitter, jitter),
                            UniformDouble(rng, -jitter, jitter),
                            UniformDouble(rng, -jitter, jitter));
    p.push_back(centre + corner + d);
  }
  return p;
}

// Family 0: a chain of 2..5 overlapping lumps along x, like the reference's blobs.
std::vector<Points> Blob(std::mt19937_64& rng) {
  const int n = static_cast<int>(UniformInt(rng, 2, 6));
  const double length = UniformDouble(rng, 0.05, 0.10);
  std::vector<Points> parts;
  for (int k = 0; k < n; ++k) {
    const double x = -length / 2 + length * k / (n - 1);
    const Eigen::Vector3d centre(x, UniformDouble(rng, -0.01, 0.01),
                                 UniformDouble(rng, -0.008, 0.008));
    const Eigen::Vector3d radii(UniformDouble(rng, 0.015, 0.028), UniformDouble(rng, 0.013, 0.025),
                                UniformDouble(rng, 0.013, 0.022));
    parts.push_back(Lump(rng, 8, centre, radii));
  }
  return parts;
}

// Family 1: an irregular box.
std::vector<Points> IrregularBox(std::mt19937_64& rng) {
  const Eigen::Vector3d h(UniformDouble(rng, 0.028, 0.065), UniformDouble(rng, 0.015, 0.03),
                          UniformDouble(rng, 0.015, 0.025));
  return {BoxCorners(rng, Eigen::Vector3d::Zero(), h, 0.003)};
}

// Family 2: a prism with 5..10 sides along x (a cylinder for many sides).
std::vector<Points> Prism(std::mt19937_64& rng) {
  const int sides = static_cast<int>(UniformInt(rng, 5, 11));
  const double radius = UniformDouble(rng, 0.014, 0.03);
  const double half_length = UniformDouble(rng, 0.025, 0.065);
  const double phase = UniformDouble(rng, 0, 2 * kPi);
  Points p;
  for (int i = 0; i < sides; ++i) {
    const double a = phase + 2 * kPi * i / sides;
    for (double x : {-half_length, half_length}) {
      p.emplace_back(x, radius * std::cos(a), radius * std::sin(a));
    }
  }
  return {p};
}

// Family 3: an L or T of two or three bars in the xy plane.
std::vector<Points> Bars(std::mt19937_64& rng) {
  const double thick = UniformDouble(rng, 0.013, 0.02);
  const double height = UniformDouble(rng, 0.013, 0.02);
  const double long_half = UniformDouble(rng, 0.035, 0.065);
  std::vector<Points> parts = {
      BoxCorners(rng, Eigen::Vector3d::Zero(), Eigen::Vector3d(long_half, thick, height), 0.001)};
  const int extra = static_cast<int>(UniformInt(rng, 1, 3));
  for (int k = 0; k < extra; ++k) {
    const double x = UniformDouble(rng, -long_half + thick, long_half - thick);
    const double cross_half = UniformDouble(rng, 0.02, 0.04);
    const double side = UniformInt(rng, 0, 2) == 0 ? -1 : 1;
    parts.push_back(BoxCorners(rng, Eigen::Vector3d(x, side * (cross_half - thick), 0),
                               Eigen::Vector3d(thick, cross_half, height), 0.001));
  }
  return parts;
}

// Family 4: one random convex hull.
std::vector<Points> RandomHull(std::mt19937_64& rng) {
  const int n = static_cast<int>(UniformInt(rng, 6, 15));
  const Eigen::Vector3d radii(UniformDouble(rng, 0.025, 0.06), UniformDouble(rng, 0.015, 0.035),
                              UniformDouble(rng, 0.015, 0.03));
  Points p = AxisEnds(Eigen::Vector3d::Zero(), radii);
  for (int i = 0; i < n; ++i) {
    // Points inside the ellipsoid, biased to its surface (radius^(1/3) of a uniform draw).
    const double r = std::cbrt(UniformDouble(rng, 0.3, 1.0));
    p.push_back((r * OnSphere(rng)).cwiseProduct(radii));
  }
  return {p};
}

// A colour whose luma is within kMinLumaContrastWithTray of the tray's becomes darker (by scaling)
// when `side` < 0.5, else lighter (by mixing with white), to a luma `depth` (in [0, 1]) of the way
// into the band of 0.15 beyond the contrast limit. A side without room for that band (darker than
// a luma of 0.05, lighter than 0.97) is never taken. Both draws are made for every object, so the
// random stream (and the shapes of later ids' draws) does not depend on the branch taken.
void KeepLumaAwayFromTray(double side, double depth, std::array<float, 3>* rgb) {
  const double tray = Luma(kTrayColor);
  const double y = Luma(*rgb);
  if (std::abs(y - tray) >= kMinLumaContrastWithTray) return;
  const bool room_below = tray - kMinLumaContrastWithTray - 0.15 >= 0.05;
  const bool room_above = tray + kMinLumaContrastWithTray + 0.15 <= 0.97;
  if ((side < 0.5 && room_below) || !room_above) {
    const double target = tray - kMinLumaContrastWithTray - 0.15 * depth;
    for (float& c : *rgb) c = static_cast<float>(c * target / y);
  } else {
    const double target = tray + kMinLumaContrastWithTray + 0.15 * depth;
    const double t = (target - y) / (1 - y);
    for (float& c : *rgb) c = static_cast<float>(c + t * (1 - c));
  }
}

// An RGB colour from hue, saturation and value in [0, 1].
std::array<float, 3> HsvToRgb(double h, double s, double v) {
  const double c = v * s;
  const double hp = h * 6;
  const double x = c * (1 - std::abs(std::fmod(hp, 2.0) - 1));
  double r = 0, g = 0, b = 0;
  if (hp < 1) {
    r = c, g = x;
  } else if (hp < 2) {
    r = x, g = c;
  } else if (hp < 3) {
    g = c, b = x;
  } else if (hp < 4) {
    g = x, b = c;
  } else if (hp < 5) {
    r = x, b = c;
  } else {
    r = c, b = x;
  }
  const double m = v - c;
  return {static_cast<float>(r + m), static_cast<float>(g + m), static_cast<float>(b + m)};
}

}  // namespace

std::vector<int> ObjectIds(bool test) {
  std::vector<int> ids;
  for (int id = 0; id < kNumObjectIds; ++id) {
    if (IsTestObject(id) == test) ids.push_back(id);
  }
  return ids;
}

ObjectShape GenerateObject(int id) {
  if (id < 0 || id >= kNumObjectIds) {
    throw std::out_of_range("GenerateObject: id must be in [0, " + std::to_string(kNumObjectIds) +
                            "), got " + std::to_string(id));
  }
  // Each id has its own stream, independent of the episode RNG.
  std::mt19937_64 rng;
  SeedRng(0x6b756b61'00000000ULL + static_cast<uint64_t>(id), rng);
  std::vector<Points> points;
  switch (UniformInt(rng, 0, 5)) {
    case 0:
      points = Blob(rng);
      break;
    case 1:
      points = IrregularBox(rng);
      break;
    case 2:
      points = Prism(rng);
      break;
    case 3:
      points = Bars(rng);
      break;
    default:
      points = RandomHull(rng);
      break;
  }

  // Move the origin to the centre of volume of all parts (overlaps counted twice).
  double volume = 0;
  Eigen::Vector3d moment = Eigen::Vector3d::Zero();
  for (const Points& p : points) {
    const ConvexHull hull = ComputeConvexHull(p);
    volume += hull.volume;
    moment += hull.volume * hull.centroid;
  }
  const Eigen::Vector3d com = moment / volume;

  ObjectShape shape;
  shape.id = id;
  shape.aabb_min = Eigen::Vector3d::Constant(1e9);
  shape.aabb_max = Eigen::Vector3d::Constant(-1e9);
  for (Points& p : points) {
    for (Eigen::Vector3d& v : p) v -= com;
    shape.parts.push_back(ComputeConvexHull(p));
    for (const Eigen::Vector3d& v : shape.parts.back().vertices) {
      shape.aabb_min = shape.aabb_min.cwiseMin(v);
      shape.aabb_max = shape.aabb_max.cwiseMax(v);
    }
  }
  shape.mass = UniformDouble(rng, 0.05, 0.2);
  shape.color = HsvToRgb(UniformDouble(rng, 0, 1), UniformDouble(rng, 0.5, 1.0),
                         UniformDouble(rng, 0.55, 1.0));
  KeepLumaAwayFromTray(UniformDouble(rng, 0, 1), UniformDouble(rng, 0, 1), &shape.color);
  return shape;
}

}  // namespace rl::envs::kuka
