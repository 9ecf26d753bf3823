// The physics of the grasping task in Bullet: ground plane, table, tray, the KUKA arm as a
// Featherstone multibody with PyBullet-style position motors, and the dropped objects.
//
// Restates the scene of PyBullet's KukaDiverseObjectEnv (spec 4.2 to 4.5): time step 1/240 s,
// 150 solver iterations, gravity -10 m/s^2 along z, PyBullet's solver defaults, joint damping
// applied as a torque every step, link inertias from the collision shapes' bounding boxes, objects
// as compounds of convex hulls with 3x box inertia, no self-collision of the arm. Bullet is
// Debian's double-precision build; no Bullet type appears in this header.
#pragma once

#include <cstdint>
#include <limits>
#include <memory>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "envs/kuka/kuka_geometry.h"
#include "envs/kuka/kuka_kinematics.h"
#include "envs/kuka/kuka_objects.h"

namespace rl::envs::kuka {

/// A PyBullet POSITION_CONTROL command (btMultiBodyJointMotor): each physics step the motor
/// drives the joint velocity towards kp * (target - q) / dt + qdot + kd * (0 - qdot), clamped to
/// +-max_velocity, with an impulse of at most force * dt. The target is clamped into the joint
/// limits. Defaults are pybullet.c's.
struct MotorCommand {
  double target = 0;      // rad.
  double force = 100000;  // N m.
  double kp = 0.1;
  double kd = 1.0;
  double max_velocity = std::numeric_limits<double>::infinity();  // rad/s.
};

/// One Bullet world with the KUKA scene. Not copyable, not thread-safe.
class KukaScene {
 public:
  static constexpr double kTimeStep = 1.0 / 240;  // s, setTimeStep.
  static constexpr int kSolverIterations = 150;   // numSolverIterations.
  static constexpr double kGravity = -10;         // m/s^2 along z.
  // Tray floor top (world z, m) and its extent (the tray's base plate, spec 4.3).
  static constexpr double kTrayFloorZ = -0.185;
  static constexpr double kTrayMinX = 0.431, kTrayMaxX = 0.849;
  static constexpr double kTrayMinY = -0.158, kTrayMaxY = 0.283;

  KukaScene();
  ~KukaScene();
  KukaScene(const KukaScene&) = delete;
  KukaScene& operator=(const KukaScene&) = delete;

  /// Builds a new world (what PyBullet's resetSimulation plus loading does): plane, table and
  /// tray, without the arm and without objects. Deterministic: the world is rebuilt from scratch,
  /// so nothing carries over from earlier episodes.
  void Reset();

  /// Adds the arm at kInitialJointPositions with zero velocity, every joint motor holding its
  /// initial position with force 200 and default gains (Kuka.reset()). Once per Reset. The
  /// methods that read or drive the arm need it. `rigid_fingertips` welds the fingertip joints
  /// (10 and 13) at 0 instead of giving them motors: two degrees of freedom fewer, about 14%
  /// cheaper per step.
  void AddArm(bool rigid_fingertips = false);
  bool has_arm() const;

  /// Adds `shape` as a dynamic body with its centre of mass at `position` (m) and rotated by `yaw`
  /// (rad) about z, at rest. Keeps a pointer to `shape`, which must stay alive until the next
  /// Reset or the scene's destruction.
  void AddObject(const ObjectShape& shape, const Eigen::Vector3d& position, double yaw);

  /// Solver iterations per physics step (numSolverIterations; kSolverIterations after Reset).
  void set_solver_iterations(int iterations);

  /// One physics step of kTimeStep: adds the joint damping torques, then steps the world.
  void StepSimulation();

  /// Sets the motor of revolute joint `joint` (0..13 except the fixed 9 and 12, else
  /// std::invalid_argument). Stays in force until changed.
  void SetMotor(int joint, const MotorCommand& command);

  /// Joint positions and velocities (rad, rad/s) in PyBullet's order; fixed joints read 0.
  JointPositions joint_positions() const;
  JointPositions joint_velocities() const;
  /// The arm's first seven joint positions.
  ArmJoints arm_joint_positions() const;

  /// World pose of link `link`'s frame (as in kuka_model.h, not its centre of mass); -1 is the
  /// base.
  Eigen::Isometry3d LinkFrame(int link) const;
  /// World position of link `link`'s centre of mass (PyBullet's getLinkState(...)[0]).
  Eigen::Vector3d LinkCenterOfMass(int link) const;

  int num_objects() const { return static_cast<int>(objects_.size()); }
  /// Pose of object i's centre-of-mass frame (PyBullet's getBasePositionAndOrientation).
  Eigen::Isometry3d ObjectPose(int i) const;
  /// Linear and angular speed of object i (m/s, rad/s).
  double ObjectSpeed(int i) const;
  double ObjectAngularSpeed(int i) const;
  const ObjectShape& object_shape(int i) const { return *objects_[i]; }
  /// True when every object moves slower than both bounds (m/s, rad/s).
  bool ObjectsAtRest(double max_speed, double max_angular_speed) const;
  /// Deactivates (Bullet's island sleeping) every object slower than both bounds (m/s, rad/s),
  /// zeroing its velocities: it costs nothing until something active touches it, which wakes it
  /// up. Returns how many objects now sleep.
  int PutRestingObjectsToSleep(double max_speed, double max_angular_speed);

  /// Physics steps since the last Reset.
  int64_t num_steps() const { return num_steps_; }

  /// Replaces *items with everything to draw at the current state: ground, table and tray
  /// (kStatic), links 0..6 and the base (kArm), gripper links 7..13 (kGripper), objects (kObject).
  void CollectDrawItems(std::vector<DrawItem>* items) const;

 private:
  struct World;  // The Bullet objects (defined in kuka_scene.cc).
  std::unique_ptr<World> world_;
  std::vector<const ObjectShape*> objects_;
  int64_t num_steps_ = 0;
};

}  // namespace rl::envs::kuka
