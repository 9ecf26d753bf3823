#include "envs/kuka/kuka_camera.h"

#include <cmath>

#include <gtest/gtest.h>
#include <Eigen/Geometry>

namespace rl::envs::kuka {
namespace {

TEST(KukaCameraTest, DefaultViewMatchesTheReferenceNumbers) {
  // Spec 4.9, computed for cameraRandom = 0: eye, up and forward.
  const CameraParams camera;
  const Eigen::Vector3d eye = EyePosition(camera);
  EXPECT_NEAR((eye - Eigen::Vector3d(-0.27680, 0.43633, 1.36904)).norm(), 0, 1e-4);
  const Eigen::Matrix4d view = ViewMatrix(camera);
  const Eigen::Vector3d up = view.block<1, 3>(1, 0).transpose();
  const Eigen::Vector3d forward = -view.block<1, 3>(2, 0).transpose();
  EXPECT_NEAR((forward - Eigen::Vector3d(0.5068, -0.2363, -0.8290)).norm(), 0, 1e-3);
  // The reference's up vector R * z is not orthogonal to forward; the look-at keeps its
  // component orthogonal to forward.
  const Eigen::Vector3d reference_up(0.75136, -0.35037, 0.55919);
  const Eigen::Vector3d expected_up =
      (reference_up - reference_up.dot(forward) * forward).normalized();
  EXPECT_NEAR((up - expected_up).norm(), 0, 1e-3);
  // The eye maps to the origin of eye coordinates.
  EXPECT_NEAR((view * eye.homogeneous()).head<3>().norm(), 0, 1e-12);
}

TEST(KukaCameraTest, ProjectionMatchesComputeProjectionMatrixFov) {
  const CameraParams camera;
  const Eigen::Matrix4d p = ProjectionMatrix(camera, 1.0);
  EXPECT_NEAR(p(0, 0), 5.67128, 1e-5);
  EXPECT_NEAR(p(1, 1), 5.67128, 1e-5);
  EXPECT_NEAR(p(2, 2), (0.01 + 10) / (0.01 - 10), 1e-12);
  EXPECT_EQ(p(3, 2), -1);
  EXPECT_NEAR(p(2, 3), 2 * 10 * 0.01 / (0.01 - 10), 1e-12);
  EXPECT_EQ(p(3, 3), 0);
  EXPECT_NEAR(ProjectionMatrix(camera, 2.0)(0, 0), 5.67128 / 2, 1e-5);
}

TEST(KukaCameraTest, OpticalAxisMeetsTheTrayNearItsCentre) {
  const CameraParams camera;
  // The target is at the image centre, and so is the point on the tray floor (z = -0.19)
  // along the optical axis, about (0.68, -0.01) (spec 4.9).
  const Eigen::Vector2d centre = ProjectToPixel(camera, 48, 48, camera.target);
  EXPECT_NEAR(centre.x(), 24, 1e-9);
  EXPECT_NEAR(centre.y(), 24, 1e-9);
  const Eigen::Vector3d eye = EyePosition(camera);
  const Eigen::Vector3d dir = (camera.target - eye).normalized();
  const Eigen::Vector3d hit = eye + dir * ((-0.19 - eye.z()) / dir.z());
  EXPECT_NEAR(hit.x(), 0.68, 0.01);
  EXPECT_NEAR(hit.y(), -0.01, 0.01);
  // Image orientation: up in the image is the camera's up vector.
  const Eigen::Vector3d up = ViewMatrix(camera).block<1, 3>(1, 0).transpose();
  EXPECT_LT(ProjectToPixel(camera, 48, 48, camera.target + 0.05 * up).y(), 24);
}

}  // namespace
}  // namespace rl::envs::kuka
