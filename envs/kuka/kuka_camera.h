// The camera of KukaDiverseObjectEnv: PyBullet's computeViewMatrixFromYawPitchRoll and
// computeProjectionMatrixFOV (spec 4.6 and 4.9), and the pixel a world point lands on.
// Eigen only; the OpenGL renderer loads these matrices as they are.
#pragma once

#include <Eigen/Core>

namespace rl::envs::kuka {

/// A camera looking at `target` from `distance` away, PyBullet style (z up, angles in degrees).
struct CameraParams {
  Eigen::Vector3d target = Eigen::Vector3d(0.23, 0.2, 0.54);  // m.
  double distance = 1.0;                                      // m.
  double yaw = 245;                                           // deg.
  double pitch = -56;                                         // deg.
  double roll = 0;                                            // deg.
  double fov = 20;                                            // Vertical field of view, deg.
  double near_plane = 0.01;                                   // m.
  double far_plane = 10;                                      // m.
};

/// computeViewMatrixFromYawPitchRoll with up axis z: the eye is target + R * (0, -distance, 0) with
/// R = Rz(yaw) Ry(roll) Rx(pitch); the result is a look-at matrix (world to eye coordinates).
Eigen::Matrix4d ViewMatrix(const CameraParams& camera);

/// The eye position of ViewMatrix.
Eigen::Vector3d EyePosition(const CameraParams& camera);

/// computeProjectionMatrixFOV(fov, aspect, near, far): an OpenGL perspective matrix.
Eigen::Matrix4d ProjectionMatrix(const CameraParams& camera, double aspect);

/// Where world point `p` appears in a width x height image of `camera`: x to the right and y
/// down from the image's top-left corner, in pixels (pixel (i, j) covers [i, i+1) x [j, j+1)).
/// Points behind the camera give non-finite or meaningless values.
Eigen::Vector2d ProjectToPixel(const CameraParams& camera, int width, int height,
                               const Eigen::Vector3d& p);

}  // namespace rl::envs::kuka
