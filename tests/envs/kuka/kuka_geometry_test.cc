#include "envs/kuka/kuka_geometry.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <set>
#include <stdexcept>
#include <vector>

#include <gtest/gtest.h>

#include "envs/kuka/kuka_objects.h"

namespace rl::envs::kuka {
namespace {

// Sum over triangles of the outward area vectors: zero for a closed surface.
Eigen::Vector3d AreaVectorSum(const Mesh& mesh) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (int t = 0; t < mesh.num_vertices(); t += 3) {
    Eigen::Vector3d p[3];
    for (int k = 0; k < 3; ++k) {
      p[k] = Eigen::Vector3d(mesh.positions[3 * (t + k)], mesh.positions[3 * (t + k) + 1],
                             mesh.positions[3 * (t + k) + 2]);
    }
    sum += (p[1] - p[0]).cross(p[2] - p[0]) / 2;
  }
  return sum;
}

// Every triangle's normal points away from `inside`.
void ExpectOutwardNormals(const Mesh& mesh, const Eigen::Vector3d& inside) {
  for (int v = 0; v < mesh.num_vertices(); ++v) {
    const Eigen::Vector3d p(mesh.positions[3 * v], mesh.positions[3 * v + 1],
                            mesh.positions[3 * v + 2]);
    const Eigen::Vector3d n(mesh.normals[3 * v], mesh.normals[3 * v + 1], mesh.normals[3 * v + 2]);
    EXPECT_GT(n.dot(p - inside), -1e-6) << "vertex " << v;
    EXPECT_NEAR(n.norm(), 1, 1e-5);
  }
}

TEST(KukaGeometryTest, ConvexHullOfACubeHasItsVolumeCentroidAndOutwardFaces) {
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < 8; ++i) points.emplace_back(i & 1 ? 2 : 0, i & 2 ? 2 : 0, i & 4 ? 2 : 0);
  points.emplace_back(1, 1, 1);  // An interior point is dropped.
  const ConvexHull hull = ComputeConvexHull(points);
  EXPECT_EQ(hull.vertices.size(), 8u);
  EXPECT_NEAR(hull.volume, 8, 1e-9);
  EXPECT_NEAR((hull.centroid - Eigen::Vector3d(1, 1, 1)).norm(), 0, 1e-9);
  EXPECT_EQ(hull.mesh.num_vertices(), 12 * 3);
  EXPECT_NEAR(AreaVectorSum(hull.mesh).norm(), 0, 1e-9);
  ExpectOutwardNormals(hull.mesh, hull.centroid);
}

TEST(KukaGeometryTest, ConvexHullRejectsDegenerateInput) {
  std::vector<Eigen::Vector3d> flat = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}};
  EXPECT_THROW(ComputeConvexHull(flat), std::invalid_argument);
  EXPECT_THROW(ComputeConvexHull(std::vector<Eigen::Vector3d>(3)), std::invalid_argument);
}

TEST(KukaGeometryTest, UnitPrimitivesAreClosedWithOutwardNormals) {
  for (const Mesh* mesh : {&UnitBoxMesh(), &UnitCylinderMesh(), &UnitSphereMesh()}) {
    EXPECT_GT(mesh->num_vertices(), 0);
    EXPECT_NEAR(AreaVectorSum(*mesh).norm(), 0, 1e-5);
    ExpectOutwardNormals(*mesh, Eigen::Vector3d::Zero());
  }
  EXPECT_EQ(UnitSphereMesh().num_vertices(), 80 * 3);
}

TEST(KukaObjectsTest, TestSetIsTheIdsEndingInZero) {
  const std::vector<int> test = ObjectIds(true);
  const std::vector<int> train = ObjectIds(false);
  EXPECT_EQ(test.size(), 100u);
  EXPECT_EQ(train.size(), 900u);
  for (int id : test) EXPECT_EQ(id % 10, 0);
  std::set<int> all(test.begin(), test.end());
  all.insert(train.begin(), train.end());
  EXPECT_EQ(all.size(), static_cast<std::size_t>(kNumObjectIds));
}

TEST(KukaObjectsTest, ObjectsAreDeterministicSmallAndDiverse) {
  std::set<std::size_t> part_counts;
  double min_mass = 1, max_mass = 0;
  for (int id = 0; id < kNumObjectIds; id += 7) {
    const ObjectShape a = GenerateObject(id);
    const ObjectShape b = GenerateObject(id);
    ASSERT_EQ(a.parts.size(), b.parts.size());
    for (std::size_t p = 0; p < a.parts.size(); ++p) {
      ASSERT_EQ(a.parts[p].vertices, b.parts[p].vertices) << "id " << id;
    }
    // Sizes like the reference's objects: longest side 5..16 cm, shortest at least 2.4 cm.
    const Eigen::Vector3d size = a.aabb_max - a.aabb_min;
    EXPECT_GE(size.maxCoeff(), 0.05) << "id " << id;
    EXPECT_LE(size.maxCoeff(), 0.16) << "id " << id;
    EXPECT_GE(size.minCoeff(), 0.024) << "id " << id;
    // The frame's origin is the centre of mass, inside the bounding box.
    EXPECT_TRUE((a.aabb_min.array() < 0).all() && (a.aabb_max.array() > 0).all()) << "id " << id;
    EXPECT_GE(a.mass, 0.05);
    EXPECT_LE(a.mass, 0.2);
    min_mass = std::min(min_mass, a.mass);
    max_mass = std::max(max_mass, a.mass);
    part_counts.insert(a.parts.size());
    for (const ConvexHull& part : a.parts) ExpectOutwardNormals(part.mesh, part.centroid);
  }
  EXPECT_GE(part_counts.size(), 4u);  // Single hulls and compounds of 2..5 parts.
  EXPECT_GT(max_mass - min_mass, 0.1);
  EXPECT_THROW(GenerateObject(-1), std::out_of_range);
  EXPECT_THROW(GenerateObject(kNumObjectIds), std::out_of_range);
}

TEST(KukaObjectsTest, EveryObjectStandsOutFromTheTrayInGrayscale) {
  const double tray = Luma(kTrayColor);
  int darker = 0, lighter = 0;
  std::set<int> hues;  // the dominant channel, a coarse hue
  for (int id = 0; id < kNumObjectIds; ++id) {
    const std::array<float, 3> c = GenerateObject(id).color;
    for (float v : c) {
      EXPECT_GE(v, 0.0f) << "id " << id;
      EXPECT_LE(v, 1.0f) << "id " << id;
    }
    const double y = Luma(c);
    EXPECT_GE(std::abs(y - tray), kMinLumaContrastWithTray - 1e-6) << "id " << id;
    (y < tray ? darker : lighter) += 1;
    hues.insert(static_cast<int>(std::max_element(c.begin(), c.end()) - c.begin()));
  }
  // On the dark tray there is no room below its luma, so every object is lighter; the colours
  // still span the hues.
  EXPECT_EQ(darker, 0);
  EXPECT_EQ(lighter, kNumObjectIds);
  EXPECT_EQ(hues.size(), 3u);
}

}  // namespace
}  // namespace rl::envs::kuka
