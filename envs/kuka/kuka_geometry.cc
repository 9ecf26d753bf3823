#include "envs/kuka/kuka_geometry.h"

#include <cmath>
#include <cstddef>
#include <numbers>
#include <stdexcept>

#include <LinearMath/btConvexHullComputer.h>

namespace rl::envs::kuka {
namespace {

Eigen::Vector3d ToEigen(const btVector3& v) { return {v.x(), v.y(), v.z()}; }

// The primitives are the convex hulls of their corner points, so that their faces wind the same
// way as every other hull.
Mesh BuildBox() {
  std::vector<Eigen::Vector3d> corners;
  for (int i = 0; i < 8; ++i) corners.emplace_back(i & 1 ? 1 : -1, i & 2 ? 1 : -1, i & 4 ? 1 : -1);
  return ComputeConvexHull(corners).mesh;
}

Mesh BuildCylinder() {
  constexpr int kSides = 16;
  std::vector<Eigen::Vector3d> rims;
  for (int i = 0; i < kSides; ++i) {
    const double a = 2 * std::numbers::pi * i / kSides;
    rims.emplace_back(std::cos(a), std::sin(a), -1);
    rims.emplace_back(std::cos(a), std::sin(a), 1);
  }
  return ComputeConvexHull(rims).mesh;
}

Mesh BuildSphere() {
  // Icosahedron with each edge split once (42 points), pushed onto the unit sphere.
  const double t = (1 + std::sqrt(5.0)) / 2;
  std::vector<Eigen::Vector3d> v = {{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0},
                                    {0, -1, t}, {0, 1, t}, {0, -1, -t}, {0, 1, -t},
                                    {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
  const std::size_t n = v.size();
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t j = i + 1; j < n; ++j) {
      // Icosahedron edges are the closest pairs (length 2 before normalisation).
      if ((v[i] - v[j]).norm() < 2.01) v.push_back((v[i] + v[j]) / 2);
    }
  }
  for (auto& p : v) p.normalize();
  return ComputeConvexHull(v).mesh;
}

}  // namespace

void Mesh::AddTriangle(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                       const Eigen::Vector3d& c) {
  Eigen::Vector3d n = (b - a).cross(c - a);
  const double norm = n.norm();
  n = norm > 0 ? Eigen::Vector3d(n / norm) : Eigen::Vector3d::UnitZ();
  for (const Eigen::Vector3d* p : {&a, &b, &c}) {
    for (int k = 0; k < 3; ++k) {
      positions.push_back(static_cast<float>((*p)[k]));
      normals.push_back(static_cast<float>(n[k]));
    }
  }
}

ConvexHull ComputeConvexHull(std::span<const Eigen::Vector3d> points) {
  if (points.size() < 4) {
    throw std::invalid_argument("ComputeConvexHull: need at least 4 points");
  }
  btConvexHullComputer computer;
  computer.compute(points.data()->data(), static_cast<int>(sizeof(Eigen::Vector3d)),
                   static_cast<int>(points.size()), 0, 0);
  if (computer.faces.size() < 4) {
    throw std::invalid_argument("ComputeConvexHull: the points are flat or degenerate");
  }
  ConvexHull hull;
  for (int i = 0; i < computer.vertices.size(); ++i) {
    hull.vertices.push_back(ToEigen(computer.vertices[i]));
  }
  // Triangulate each face as a fan around its first vertex; accumulate the volume and centroid
  // of the tetrahedra from a point inside the hull.
  Eigen::Vector3d inside = Eigen::Vector3d::Zero();
  for (const auto& v : hull.vertices) inside += v;
  inside /= static_cast<double>(hull.vertices.size());
  Eigen::Vector3d moment = Eigen::Vector3d::Zero();
  for (int f = 0; f < computer.faces.size(); ++f) {
    const btConvexHullComputer::Edge* first = &computer.edges[computer.faces[f]];
    const Eigen::Vector3d a = hull.vertices[first->getSourceVertex()];
    const btConvexHullComputer::Edge* edge = first->getNextEdgeOfFace();
    while (edge->getTargetVertex() != first->getSourceVertex()) {
      const Eigen::Vector3d b = hull.vertices[edge->getSourceVertex()];
      const Eigen::Vector3d c = hull.vertices[edge->getTargetVertex()];
      hull.mesh.AddTriangle(a, b, c);
      const double tet = (a - inside).dot((b - inside).cross(c - inside)) / 6;
      hull.volume += tet;
      moment += tet * (a + b + c + inside) / 4;
      edge = edge->getNextEdgeOfFace();
    }
  }
  hull.centroid = hull.volume > 0 ? Eigen::Vector3d(moment / hull.volume) : inside;
  return hull;
}

const Mesh& UnitBoxMesh() {
  static const Mesh mesh = BuildBox();
  return mesh;
}

const Mesh& UnitCylinderMesh() {
  static const Mesh mesh = BuildCylinder();
  return mesh;
}

const Mesh& UnitSphereMesh() {
  static const Mesh mesh = BuildSphere();
  return mesh;
}

}  // namespace rl::envs::kuka
