#include "envs/kuka/kuka_kinematics.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include <Eigen/Cholesky>

namespace rl::envs::kuka {
namespace {

// Pose of link i's frame given its parent's pose and its joint position.
Eigen::Isometry3d ChildFrame(const Eigen::Isometry3d& parent, int i, double q) {
  const KukaModel& m = Model();
  const LinkSpec& link = m.links[i];
  Eigen::Isometry3d t = parent * m.parent_to_link[i];
  if (link.revolute) t.linear() = t.linear() * Eigen::AngleAxisd(q, link.axis).matrix();
  return t;
}

// Frames of the arm links 0..6 (each arm link's parent is the previous one).
std::array<Eigen::Isometry3d, kNumArmJoints> ArmFrames(const ArmJoints& q) {
  std::array<Eigen::Isometry3d, kNumArmJoints> frames;
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  for (int i = 0; i < kNumArmJoints; ++i) {
    t = ChildFrame(t, i, q[i]);
    frames[i] = t;
  }
  return frames;
}

// Rotation vector (axis * angle) of a rotation matrix.
Eigen::Vector3d RotationVector(const Eigen::Matrix3d& r) {
  const Eigen::AngleAxisd aa(r);
  return aa.axis() * aa.angle();
}

}  // namespace

std::array<Eigen::Isometry3d, kNumLinks> LinkFrames(const JointPositions& q) {
  const KukaModel& m = Model();
  std::array<Eigen::Isometry3d, kNumLinks> frames;
  // Parents always come before their children in the link list.
  for (int i = 0; i < kNumLinks; ++i) {
    const int parent = m.links[i].parent;
    const Eigen::Isometry3d base = Eigen::Isometry3d::Identity();
    frames[i] = ChildFrame(parent < 0 ? base : frames[parent], i, q[i]);
  }
  return frames;
}

Eigen::Isometry3d EndEffectorFrame(const ArmJoints& q) { return ArmFrames(q)[kEndEffectorLink]; }

ArmJacobian EndEffectorJacobian(const ArmJoints& q) {
  const KukaModel& m = Model();
  const std::array<Eigen::Isometry3d, kNumArmJoints> frames = ArmFrames(q);
  const Eigen::Vector3d tip = frames[kEndEffectorLink].translation();
  ArmJacobian jac;
  // Column i: the joint axis in the world (angular part) and axis x (tip - joint origin).
  for (int i = 0; i < kNumArmJoints; ++i) {
    const Eigen::Vector3d axis = frames[i].linear() * m.links[i].axis;
    jac.block<3, 1>(0, i) = axis.cross(tip - frames[i].translation());
    jac.block<3, 1>(3, i) = axis;
  }
  return jac;
}

Eigen::Matrix3d GripperDownOrientation() {
  return Eigen::AngleAxisd(-std::numbers::pi, Eigen::Vector3d::UnitY()).matrix();
}

IkResult SolveIk(const Eigen::Vector3d& position, const Eigen::Matrix3d& orientation,
                 const ArmJoints& start, const IkOptions& options) {
  IkResult result;
  result.q = start;
  const double lambda2 = options.damping * options.damping;
  for (int iteration = 0;; ++iteration) {
    // Pose error at the current estimate.
    const Eigen::Isometry3d frame = EndEffectorFrame(result.q);
    Eigen::Matrix<double, 6, 1> error;
    error.head<3>() = position - frame.translation();
    error.tail<3>() = RotationVector(orientation * frame.linear().transpose());
    result.position_error = error.head<3>().norm();
    result.orientation_error = error.tail<3>().norm();
    result.iterations = iteration;
    if ((result.position_error < options.tolerance &&
         result.orientation_error < options.tolerance) ||
        iteration >= options.max_iterations) {
      return result;
    }
    // Damped least-squares step, limited per joint.
    const ArmJacobian jac = EndEffectorJacobian(result.q);
    const Eigen::Matrix<double, 6, 6> jjt =
        jac * jac.transpose() + lambda2 * Eigen::Matrix<double, 6, 6>::Identity();
    ArmJoints dq = jac.transpose() * jjt.ldlt().solve(error);
    const double largest = dq.cwiseAbs().maxCoeff();
    if (largest > options.max_joint_step) dq *= options.max_joint_step / largest;
    result.q += dq;
  }
}

}  // namespace rl::envs::kuka
