// Forward kinematics, the end-effector Jacobian and damped-least-squares inverse kinematics of the
// KUKA iiwa model in kuka_model.h, on Eigen (double).
//
// This is what PyBullet's calculateInverseKinematics does for KukaDiverseObjectEnv (spec 4.4):
// the IK2_VEL_DLS_WITH_ORIENTATION solver, target position and orientation of
// lbr_iiwa_link_7's frame, iterated from the current joint positions until the residual is
// below a threshold. The null-space variant is not used by the reference and is not provided.
// All frames are world frames with the arm's base frame at the world origin.
#pragma once

#include <array>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "envs/kuka/kuka_model.h"

namespace rl::envs::kuka {

/// Positions of the seven arm joints J0..J6, radians.
using ArmJoints = Eigen::Matrix<double, kNumArmJoints, 1>;
/// Positions of all joints 0..13 in PyBullet's order (entries of fixed joints are ignored).
using JointPositions = std::array<double, kNumLinks>;
/// Geometric Jacobian of the end-effector frame: rows 0..2 map joint rates to the linear velocity
/// of the frame's origin, rows 3..5 to its angular velocity, both in the world frame.
using ArmJacobian = Eigen::Matrix<double, 6, kNumArmJoints>;

/// World poses of the frames (not the centres of mass) of links 0..13 for joint positions `q`.
/// O(kNumLinks).
std::array<Eigen::Isometry3d, kNumLinks> LinkFrames(const JointPositions& q);

/// World pose of lbr_iiwa_link_7's frame (link 6) for arm joint positions `q`.
Eigen::Isometry3d EndEffectorFrame(const ArmJoints& q);

/// The Jacobian of EndEffectorFrame at `q`.
ArmJacobian EndEffectorJacobian(const ArmJoints& q);

/// The orientation that Kuka.applyAction asks of the end effector: quaternion from Euler angles
/// (0, -pi, 0), i.e. a rotation of pi about y, so that the gripper points straight down.
Eigen::Matrix3d GripperDownOrientation();

/// Options of SolveIk.
struct IkOptions {
  int max_iterations = 20;  // PyBullet's current limit.
  double tolerance = 1e-4;  // Stop when the position error (m) is below this (PyBullet's
                            // residual threshold) and the orientation error (rad) too.
  double damping = 1e-3;  // lambda of the damped least squares: dq = J^T (J J^T + lambda^2 I)^-1 e.
  double max_joint_step = 0.5;  // Largest change of one joint per iteration, rad (keeps the
                                // first iterations from far targets stable).
};

/// What SolveIk found.
struct IkResult {
  ArmJoints q =
      ArmJoints::Zero();         // Joint positions, not clamped to the joint limits (as PyBullet).
  int iterations = 0;            // Iterations used.
  double position_error = 0;     // |target - reached| of the frame origin, m.
  double orientation_error = 0;  // Angle of the remaining rotation, rad.
};

/// Damped-least-squares IK for lbr_iiwa_link_7's frame to reach `position` with `orientation`,
/// starting from `start`. Each iteration computes the pose error e (position difference and the
/// rotation vector of orientation * current^T), solves dq = J^T (J J^T + lambda^2 I)^-1 e and
/// adds it (scaled down if a joint would move by more than max_joint_step). O(iterations).
IkResult SolveIk(const Eigen::Vector3d& position, const Eigen::Matrix3d& orientation,
                 const ArmJoints& start, const IkOptions& options = {});

}  // namespace rl::envs::kuka
