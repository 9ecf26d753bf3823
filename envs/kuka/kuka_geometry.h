// Triangle meshes for drawing the KUKA scene, and convex hulls of point sets (for the tray and the
// procedurally generated objects, which collide as convex hulls and are drawn as the same hulls).
#pragma once

#include <array>
#include <span>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace rl::envs::kuka {

/// A flat-shaded triangle soup: three vertices per triangle, each with the face's outward normal.
/// Coordinates in metres in the owner's frame.
struct Mesh {
  std::vector<float> positions;  // x, y, z per vertex.
  std::vector<float> normals;    // Unit outward normal per vertex.

  int num_vertices() const { return static_cast<int>(positions.size() / 3); }
  /// Appends one triangle (counter-clockwise seen from outside) with its face normal.
  void AddTriangle(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c);
};

/// Which part of the scene a drawn mesh belongs to (lets tests draw parts of the scene alone).
enum class DrawGroup { kStatic, kArm, kGripper, kObject };

/// One mesh to draw: `transform` maps mesh coordinates to the world (it may scale, for the unit
/// primitives). The mesh must outlive the draw call.
struct DrawItem {
  const Mesh* mesh = nullptr;
  Eigen::Affine3d transform = Eigen::Affine3d::Identity();
  std::array<float, 3> color = {0.6f, 0.6f, 0.6f};  // RGB in [0, 1].
  DrawGroup group = DrawGroup::kStatic;
};

/// The convex hull of a point set.
struct ConvexHull {
  std::vector<Eigen::Vector3d> vertices;  // Hull vertices (a subset of the input points).
  Mesh mesh;                              // Its faces, triangulated as fans.
  double volume = 0;                      // m^3.
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();  // Centre of volume.
};

/// Computes the convex hull of `points` (at least 4 points not in one plane, else
/// std::invalid_argument). Uses Bullet's btConvexHullComputer. O(n log n).
ConvexHull ComputeConvexHull(std::span<const Eigen::Vector3d> points);

/// Meshes of the unit primitives, built once (thread-safe): a cube with half extents 1, a
/// cylinder of radius 1 and half length 1 along z (16 sides), a sphere of radius 1 (an
/// icosphere with 80 faces). Scale them with the draw transform.
const Mesh& UnitBoxMesh();
const Mesh& UnitCylinderMesh();
const Mesh& UnitSphereMesh();

}  // namespace rl::envs::kuka
