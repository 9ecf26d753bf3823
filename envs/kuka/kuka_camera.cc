#include "envs/kuka/kuka_camera.h"

#include <cmath>
#include <numbers>

#include <Eigen/Geometry>

namespace rl::envs::kuka {
namespace {

double Radians(double degrees) { return degrees * std::numbers::pi / 180; }

Eigen::Matrix3d CameraRotation(const CameraParams& c) {
  return (Eigen::AngleAxisd(Radians(c.yaw), Eigen::Vector3d::UnitZ()) *
          Eigen::AngleAxisd(Radians(c.roll), Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(Radians(c.pitch), Eigen::Vector3d::UnitX()))
      .matrix();
}

}  // namespace

Eigen::Vector3d EyePosition(const CameraParams& camera) {
  return camera.target + CameraRotation(camera) * Eigen::Vector3d(0, -camera.distance, 0);
}

Eigen::Matrix4d ViewMatrix(const CameraParams& camera) {
  const Eigen::Vector3d eye = EyePosition(camera);
  const Eigen::Vector3d up = CameraRotation(camera) * Eigen::Vector3d::UnitZ();
  const Eigen::Vector3d f = (camera.target - eye).normalized();
  const Eigen::Vector3d s = f.cross(up).normalized();
  const Eigen::Vector3d u = s.cross(f);
  Eigen::Matrix4d view = Eigen::Matrix4d::Identity();
  view.block<1, 3>(0, 0) = s.transpose();
  view.block<1, 3>(1, 0) = u.transpose();
  view.block<1, 3>(2, 0) = -f.transpose();
  view(0, 3) = -s.dot(eye);
  view(1, 3) = -u.dot(eye);
  view(2, 3) = f.dot(eye);
  return view;
}

Eigen::Matrix4d ProjectionMatrix(const CameraParams& camera, double aspect) {
  const double y_scale = 1 / std::tan(Radians(camera.fov) / 2);
  const double n = camera.near_plane;
  const double f = camera.far_plane;
  Eigen::Matrix4d proj = Eigen::Matrix4d::Zero();
  proj(0, 0) = y_scale / aspect;
  proj(1, 1) = y_scale;
  proj(2, 2) = (n + f) / (n - f);
  proj(3, 2) = -1;
  proj(2, 3) = 2 * f * n / (n - f);
  return proj;
}

Eigen::Vector2d ProjectToPixel(const CameraParams& camera, int width, int height,
                               const Eigen::Vector3d& p) {
  const Eigen::Vector4d clip = ProjectionMatrix(camera, static_cast<double>(width) / height) *
                               ViewMatrix(camera) * p.homogeneous();
  const double x = clip.x() / clip.w();
  const double y = clip.y() / clip.w();
  return {(x + 1) / 2 * width, (1 - y) / 2 * height};
}

}  // namespace rl::envs::kuka
