// The KUKA LBR iiwa 7-joint arm with the two-finger gripper of PyBullet's
// pybullet_data/kuka_iiwa/kuka_with_gripper2.sdf, as data: link poses at the zero configuration,
// joint axes and limits, masses and centres of mass, and primitive collision/visual shapes.
//
// Restated from the facts in ../shared/specs/environments.md section 4.5 (bulletphysics/bullet3,
// examples/pybullet/gym/pybullet_data/kuka_iiwa/kuka_with_gripper2.sdf). The STL meshes are
// replaced by boxes, cylinders and spheres sized from the meshes' bounding boxes (spec table
// "suggested primitive"). Link numbering follows PyBullet: link i is the child of joint i, so
// link 6 is lbr_iiwa_link_7 (the end effector, kukaEndEffectorIndex) and link 7 is the gripper's
// base_link. The base (lbr_iiwa_link_0) is separate and its frame sits at the world origin.
// Eigen only; Bullet and OpenGL code read this table.
#pragma once

#include <array>
#include <string_view>
#include <vector>

#include <Eigen/Geometry>

namespace rl::envs::kuka {

/// Number of links (and joints) after the base, as PyBullet numbers them: 0..6 the arm joints
/// J0..J6, 7 the gripper yaw, 8..13 the fingers (9 and 12 fixed).
inline constexpr int kNumLinks = 14;
/// The seven arm joints are links 0..6.
inline constexpr int kNumArmJoints = 7;
/// lbr_iiwa_link_7: the link that inverse kinematics positions (kukaEndEffectorIndex).
inline constexpr int kEndEffectorLink = 6;
/// Joint indices of the gripper (PyBullet's numbering).
inline constexpr int kGripperYawJoint = 7;
inline constexpr int kLeftFingerJoint = 8;
inline constexpr int kLeftFingerBaseLink = 9;
inline constexpr int kLeftTipJoint = 10;
inline constexpr int kRightFingerJoint = 11;
inline constexpr int kRightFingerBaseLink = 12;
inline constexpr int kRightTipJoint = 13;

/// The joint positions (rad) that Kuka.reset() sets, one per joint 0..13 (fixed joints 0).
inline constexpr std::array<double, kNumLinks> kInitialJointPositions = {
    0.006418, 0.413184,  -0.011401, -1.589317, 0.005379, 1.137684, -0.006539,
    0.000048, -0.299912, 0.000000,  -0.000043, 0.299960, 0.000000, -0.000200};

/// A primitive shape attached to a link, used both for collision and for drawing.
struct Shape {
  enum class Kind { kBox, kCylinder, kSphere };
  Kind kind = Kind::kBox;
  /// kBox: half extents along x, y, z. kCylinder: (radius, radius, half length), the cylinder's
  /// axis is the local z axis of `pose`. kSphere: (radius, radius, radius).
  Eigen::Vector3d size = Eigen::Vector3d::Zero();
  /// Pose of the shape in the link frame.
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
};

/// One rigid link and the joint that attaches it to its parent.
struct LinkSpec {
  std::string_view name;
  int parent = -1;  // Index of the parent link; -1 is the base.
  // Pose of the link frame in the model frame at the zero configuration (the SDF <pose>):
  // position in metres, rpy in radians with R = Rz(yaw) * Ry(pitch) * Rx(roll).
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  Eigen::Vector3d rpy = Eigen::Vector3d::Zero();
  bool revolute = false;                            // False: a fixed joint.
  Eigen::Vector3d axis = Eigen::Vector3d::UnitZ();  // Joint axis in this link's frame.
  bool limited = false;                             // Joint limits apply (revolute only).
  double lower = 0;                                 // Limits in radians.
  double upper = 0;
  double damping = 0;  // Joint damping, N m s/rad: torque -damping * qdot every physics step.
  double mass = 0;     // kg; 0 only for the fixed base.
  Eigen::Vector3d com = Eigen::Vector3d::Zero();  // Centre of mass in the link frame.
  double lateral_friction = 0.5;   // Coulomb friction coefficient (SDF <contact> or default).
  double spinning_friction = 0.0;  // Torsional friction (SDF <contact>), metres.
  std::array<float, 3> color = {0.6f, 0.6f, 0.6f};  // Diffuse colour, RGB in [0, 1].
  std::vector<Shape> shapes;
};

/// The whole arm: the fixed base and links 0..13. Immutable after construction.
struct KukaModel {
  LinkSpec base;
  std::array<LinkSpec, kNumLinks> links;
  // Transform from the parent's frame to this link's frame at the zero configuration
  // (inverse(parent pose) * pose), precomputed from the poses above.
  std::array<Eigen::Isometry3d, kNumLinks> parent_to_link;
};

/// The model of kuka_with_gripper2.sdf, built once on first use. Thread-safe.
const KukaModel& Model();

/// Rotation matrix from roll, pitch, yaw (radians): Rz(yaw) * Ry(pitch) * Rx(roll).
Eigen::Matrix3d RpyToMatrix(const Eigen::Vector3d& rpy);

}  // namespace rl::envs::kuka
