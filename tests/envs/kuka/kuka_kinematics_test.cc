#include "envs/kuka/kuka_kinematics.h"

#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "envs/kuka/kuka_model.h"
#include "envs/rng.h"

namespace rl::envs::kuka {
namespace {

ArmJoints InitialArm() {
  ArmJoints q;
  for (int i = 0; i < kNumArmJoints; ++i) q[i] = kInitialJointPositions[i];
  return q;
}

TEST(KukaKinematicsTest, StraightUpPoseStacksThePublishedSegmentLengths) {
  JointPositions q{};
  const auto frames = LinkFrames(q);
  // Heights of the joint frames above the base, from the SDF (spec 4.5).
  const double heights[] = {0.1575, 0.36, 0.5645, 0.78, 0.9645, 1.18, 1.261, 1.305};
  for (int i = 0; i < 8; ++i) {
    EXPECT_NEAR(frames[i].translation().z(), heights[i], 1e-9) << "link " << i;
    EXPECT_NEAR(frames[i].translation().head<2>().norm(), 0, 1e-9) << "link " << i;
  }
  // Segment lengths J0->J1 ... J6->gripper.
  const double segments[] = {0.2025, 0.2045, 0.2155, 0.1845, 0.2155, 0.081, 0.044};
  for (int i = 0; i < 7; ++i) {
    EXPECT_NEAR((frames[i + 1].translation() - frames[i].translation()).norm(), segments[i], 1e-9);
  }
  // Finger pivots 0.045 above the gripper base, the finger bases 0.08 above the pivots.
  EXPECT_NEAR(
      frames[kLeftFingerJoint].translation().z() - frames[kGripperYawJoint].translation().z(),
      0.045, 1e-9);
  EXPECT_NEAR(
      frames[kLeftFingerBaseLink].translation().z() - frames[kLeftFingerJoint].translation().z(),
      0.08, 1e-9);
  EXPECT_NEAR(EndEffectorFrame(ArmJoints::Zero()).translation().z(), 1.261, 1e-9);
}

TEST(KukaKinematicsTest, JointAxesAtZeroPointAlongThePublishedWorldAxes) {
  JointPositions q{};
  const auto frames = LinkFrames(q);
  const Eigen::Vector3d expected[] = {Eigen::Vector3d::UnitZ(), Eigen::Vector3d::UnitY(),
                                      Eigen::Vector3d::UnitZ(), -Eigen::Vector3d::UnitY(),
                                      Eigen::Vector3d::UnitZ(), Eigen::Vector3d::UnitY(),
                                      Eigen::Vector3d::UnitZ(), Eigen::Vector3d::UnitZ()};
  for (int i = 0; i < 8; ++i) {
    const Eigen::Vector3d axis = frames[i].linear() * Model().links[i].axis;
    EXPECT_NEAR((axis - expected[i]).norm(), 0, 1e-4) << "joint " << i;
  }
}

TEST(KukaKinematicsTest, InitialPosePutsTheGripperAboveTheTrayPointingDown) {
  // Spec 4.5 (derived): link_7 frame at (0.532, -0.001, 0.496), z axis down; its COM 0.02 lower;
  // the gripper base at z 0.452.
  JointPositions q = kInitialJointPositions;
  const auto frames = LinkFrames(q);
  const Eigen::Isometry3d& ee = frames[kEndEffectorLink];
  EXPECT_NEAR(ee.translation().x(), 0.532, 1e-3);
  EXPECT_NEAR(ee.translation().y(), -0.001, 1e-3);
  EXPECT_NEAR(ee.translation().z(), 0.496, 1e-3);
  EXPECT_NEAR((ee.linear().col(2) - Eigen::Vector3d(0, 0, -1)).norm(), 0, 2e-3);
  EXPECT_NEAR((ee * Model().links[kEndEffectorLink].com).z(), 0.476, 1e-3);
  EXPECT_NEAR(frames[kGripperYawJoint].translation().z(), 0.452, 1e-3);
  EXPECT_NEAR((EndEffectorFrame(InitialArm()).translation() - ee.translation()).norm(), 0, 1e-12);
}

TEST(KukaKinematicsTest, JacobianMatchesFiniteDifferences) {
  std::mt19937_64 rng(7);
  for (int trial = 0; trial < 5; ++trial) {
    ArmJoints q;
    for (int i = 0; i < kNumArmJoints; ++i) q[i] = UniformDouble(rng, -1.5, 1.5);
    const ArmJacobian jac = EndEffectorJacobian(q);
    const Eigen::Isometry3d f0 = EndEffectorFrame(q);
    const double h = 1e-6;
    for (int i = 0; i < kNumArmJoints; ++i) {
      ArmJoints qh = q;
      qh[i] += h;
      const Eigen::Isometry3d f1 = EndEffectorFrame(qh);
      const Eigen::Vector3d v = (f1.translation() - f0.translation()) / h;
      const Eigen::AngleAxisd dr(f1.linear() * f0.linear().transpose());
      const Eigen::Vector3d w = dr.axis() * dr.angle() / h;
      EXPECT_NEAR((v - jac.block<3, 1>(0, i)).norm(), 0, 1e-5);
      EXPECT_NEAR((w - jac.block<3, 1>(3, i)).norm(), 0, 1e-5);
    }
  }
}

TEST(KukaKinematicsTest, IkReachesRandomTargetsInTheTrayWorkspaceWithinAMillimetre) {
  std::mt19937_64 rng(11);
  const Eigen::Matrix3d down = GripperDownOrientation();
  IkOptions options;
  options.max_iterations = 100;
  for (int trial = 0; trial < 200; ++trial) {
    // The env's clamps on x and y, and heights from the start (0.5) down to below the grasp
    // trigger.
    const Eigen::Vector3d target(UniformDouble(rng, 0.5, 0.65), UniformDouble(rng, -0.17, 0.22),
                                 UniformDouble(rng, 0.0, 0.55));
    const IkResult ik = SolveIk(target, down, InitialArm(), options);
    const Eigen::Isometry3d reached = EndEffectorFrame(ik.q);
    EXPECT_LT((reached.translation() - target).norm(), 1e-3) << target.transpose();
    EXPECT_LT(Eigen::AngleAxisd(reached.linear() * down.transpose()).angle(), 1e-3);
    EXPECT_LT(ik.iterations, options.max_iterations);
  }
}

TEST(KukaKinematicsTest, IkWithTheReferenceTwentyIterationsTracksSmallSteps) {
  // The env moves the target by at most 6 cm a step and starts IK from the current joints.
  std::mt19937_64 rng(3);
  ArmJoints q = InitialArm();
  Eigen::Vector3d target(0.537, 0.0, 0.5);
  for (int step = 0; step < 50; ++step) {
    target.x() = std::clamp(target.x() + UniformDouble(rng, -0.06, 0.06), 0.5, 0.65);
    target.y() = std::clamp(target.y() + UniformDouble(rng, -0.06, 0.06), -0.17, 0.22);
    target.z() = std::clamp(target.z() + UniformDouble(rng, -0.06, 0.06), 0.0, 0.55);
    const IkResult ik = SolveIk(target, GripperDownOrientation(), q);
    EXPECT_LT(ik.position_error, 1e-4);
    q = ik.q;
  }
}

}  // namespace
}  // namespace rl::envs::kuka
