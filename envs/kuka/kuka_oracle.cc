#include "envs/kuka/kuka_oracle.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

namespace rl::envs::kuka {
namespace {

using Env = KukaDiverseObjectEnv;

// The angle between two horizontal directions, folded to [0, pi/2] (a gripper closing along d
// is the same as one closing along -d).
double AxisAngle(const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  const double c = std::abs(a.normalized().dot(b.normalized()));
  return std::acos(std::clamp(c, 0.0, 1.0));
}

// The horizontal direction of object i's largest extent.
Eigen::Vector2d LongAxis(const KukaScene& scene, int i) {
  const ObjectShape& shape = scene.object_shape(i);
  const Eigen::Matrix3d rot = scene.ObjectPose(i).linear();
  const Eigen::Vector3d extent = shape.aabb_max - shape.aabb_min;
  Eigen::Vector2d best = Eigen::Vector2d::UnitX();
  double best_length = -1;
  for (int k = 0; k < 3; ++k) {
    const Eigen::Vector3d axis = rot.col(k) * extent[k];
    const double length = axis.head<2>().norm();
    if (length > best_length) {
      best_length = length;
      best = axis.head<2>();
    }
  }
  return best;
}

}  // namespace

int OracleAction(const KukaDiverseObjectEnv& env, const OracleOptions& options) {
  const KukaScene& scene = env.scene();
  const double dv = env.config().dv;
  const Eigen::Vector2d target = env.end_effector_target().head<2>();
  // Where the grasp point sits relative to the end effector (it follows the target).
  const Eigen::Vector2d offset =
      (env.GraspPoint() - scene.LinkFrame(kEndEffectorLink).translation()).head<2>();

  // The object whose grasp target is nearest, penalising targets outside the workspace.
  int best = -1;
  double best_cost = std::numeric_limits<double>::infinity();
  Eigen::Vector2d best_goal = target;
  for (int i = 0; i < scene.num_objects(); ++i) {
    const Eigen::Vector2d wanted = scene.ObjectPose(i).translation().head<2>() - offset;
    const Eigen::Vector2d goal(std::clamp(wanted.x(), Env::kMinX, Env::kMaxX),
                               std::clamp(wanted.y(), Env::kMinY, Env::kMaxY));
    const double cost = (goal - target).norm() + 3 * (goal - wanted).norm();
    if (cost < best_cost) {
      best_cost = cost;
      best = i;
      best_goal = goal;
    }
  }
  if (best < 0) return 0;

  // Move along the axis with the larger error while it exceeds half a step.
  const Eigen::Vector2d error = best_goal - target;
  if (std::max(std::abs(error.x()), std::abs(error.y())) > dv / 2) {
    if (std::abs(error.x()) >= std::abs(error.y())) return error.x() > 0 ? 2 : 1;
    return error.y() > 0 ? 4 : 3;
  }

  // Turn so that the fingers close across the object's long axis.
  if (options.align_gripper) {
    const Eigen::Isometry3d gripper = scene.LinkFrame(kGripperYawJoint);
    const Eigen::Vector3d closing = gripper.linear().col(0);
    const Eigen::Vector2d across = LongAxis(scene, best);
    // The fingers should close along the long axis' normal, i.e. at pi/2 from it.
    auto misalignment = [&](double turn) {
      const Eigen::Vector3d d = Eigen::AngleAxisd(turn, gripper.linear().col(2)) * closing;
      return std::numbers::pi / 2 - AxisAngle(d.head<2>(), across);
    };
    const double now = misalignment(0);
    const double minus = misalignment(-Env::kGraspAngle);
    const double plus = misalignment(Env::kGraspAngle);
    if (std::min(minus, plus) < now - 0.05) return minus < plus ? 5 : 6;
  }
  return 0;
}

}  // namespace rl::envs::kuka
