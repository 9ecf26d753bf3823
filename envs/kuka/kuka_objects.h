// The procedurally generated object family of the grasping task, standing in for PyBullet's
// random_urdfs (1000 "blob" objects made of a few convex pieces, scaled to about 3 x 6 x 12 cm,
// split into training and test sets by folder name; spec 4.7).
//
// Object `id` (0..999) is built from its own RNG seeded with the id, so an id always gives the same
// object, independently of any episode seed. Five families, drawn per id: blobs of 2..5 convex
// lumps in a chain (like the reference's objects), irregular boxes, prisms (5..10 sides),
// L/T shapes of two or three bars, and single random convex hulls. Sizes: longest dimension about
// 5..15 cm, smallest at least 2.4 cm. Mass uniform in [0.05, 0.2] kg (the reference uses 0.1 for
// all); lateral friction 1.0 as in the reference URDFs; a random saturated colour whose luma
// (Rec. 601, as in a grayscale conversion) differs from the tray's by at least
// kMinLumaContrastWithTray, so that every object stays visible in grayscale camera frames.
#pragma once

#include <array>
#include <vector>

#include <Eigen/Core>

#include "envs/kuka/kuka_geometry.h"

namespace rl::envs::kuka {

/// The tray's colour (RGB in [0, 1]; drawn by the scene) and the least luma difference between an
/// object's colour and it. A DQN sees grayscale frames: on the earlier mid-grey tray (luma 0.57)
/// the 0.6-grey gripper differed by about 8 of 255 levels where it covered the tray, so the network
/// could not see where the gripper was, and without the contrast limit about a third of the
/// objects vanished too. The reference's tray is textured, in a colour not known here; a dark tray
/// (luma 0.15) keeps the gripper, the arm and every object apart from it.
inline constexpr std::array<float, 3> kTrayColor = {0.13f, 0.15f, 0.19f};
inline constexpr double kMinLumaContrastWithTray = 0.25;

/// Rec. 601 luma of an RGB colour in [0, 1] (the weights of OpenCV's RGB-to-gray conversion).
inline double Luma(const std::array<float, 3>& rgb) {
  return 0.299 * rgb[0] + 0.587 * rgb[1] + 0.114 * rgb[2];
}

/// Number of object ids; valid ids are 0 .. kNumObjectIds - 1.
inline constexpr int kNumObjectIds = 1000;

/// Held-out test objects are the ids ending in 0 (100 of them), as the reference's test pool is
/// the folders ending in 0; the other 900 are the training objects.
inline bool IsTestObject(int id) { return id % 10 == 0; }

/// The ids of the test set (test = true) or of the training set, ascending.
std::vector<int> ObjectIds(bool test);

/// One generated object. Frame: origin at the centre of mass (the volume centroid of the parts).
struct ObjectShape {
  int id = -1;
  std::vector<ConvexHull> parts;  // Convex pieces in the object frame; they collide as a compound.
  double mass = 0.1;              // kg.
  double lateral_friction = 1.0;
  Eigen::Vector3d aabb_min = Eigen::Vector3d::Zero();  // Bounding box of all parts, object frame.
  Eigen::Vector3d aabb_max = Eigen::Vector3d::Zero();
  std::array<float, 3> color = {0.5f, 0.5f, 0.5f};  // RGB in [0, 1].
};

/// Builds object `id` (0 <= id < kNumObjectIds, else std::out_of_range). Deterministic. About
/// 0.1 ms.
ObjectShape GenerateObject(int id);

}  // namespace rl::envs::kuka
