#include "envs/kuka/kuka_scene.h"

#include <cmath>

#include <gtest/gtest.h>

#include "envs/kuka/kuka_kinematics.h"
#include "envs/kuka/kuka_model.h"
#include "envs/kuka/kuka_objects.h"

namespace rl::envs::kuka {
namespace {

// Bullet's link poses equal our forward kinematics at the scene's joint positions.
void ExpectBulletMatchesKinematics(const KukaScene& scene) {
  const auto frames = LinkFrames(scene.joint_positions());
  for (int i = 0; i < kNumLinks; ++i) {
    const Eigen::Isometry3d bullet = scene.LinkFrame(i);
    EXPECT_NEAR((bullet.translation() - frames[i].translation()).norm(), 0, 1e-6) << "link " << i;
    EXPECT_NEAR(Eigen::AngleAxisd(bullet.linear() * frames[i].linear().transpose()).angle(), 0,
                1e-6)
        << "link " << i;
  }
  EXPECT_NEAR((scene.LinkFrame(-1).translation()).norm(), 0, 1e-9);
}

TEST(KukaSceneTest, BulletMultibodyMatchesForwardKinematics) {
  for (bool rigid_fingertips : {false, true}) {
    SCOPED_TRACE(rigid_fingertips ? "rigid fingertips" : "fingertip motors");
    KukaScene scene;
    scene.AddArm(rigid_fingertips);
    ExpectBulletMatchesKinematics(scene);
    for (int i = 0; i < 240; ++i) scene.StepSimulation();
    ExpectBulletMatchesKinematics(scene);
  }
  KukaScene scene;
  scene.AddArm();
  // Drive the arm somewhere else and compare again.
  const double targets[] = {0.3, 0.6, -0.2, -1.2, 0.3, 0.9, 0.5};
  for (int j = 0; j < kNumArmJoints; ++j) {
    scene.SetMotor(j, MotorCommand{.target = targets[j], .force = 200, .kp = 0.3});
  }
  for (int i = 0; i < 240; ++i) scene.StepSimulation();
  ExpectBulletMatchesKinematics(scene);
  EXPECT_NEAR(scene.joint_positions()[0], 0.3, 0.01);
  const Eigen::Vector3d com = scene.LinkCenterOfMass(kEndEffectorLink);
  EXPECT_NEAR((com - scene.LinkFrame(kEndEffectorLink) * Model().links[6].com).norm(), 0, 1e-9);
}

TEST(KukaSceneTest, ArmHoldsItsInitialPose) {
  KukaScene scene;
  scene.AddArm();
  for (int i = 0; i < 480; ++i) scene.StepSimulation();
  const JointPositions q = scene.joint_positions();
  for (int i = 0; i < kNumLinks; ++i) {
    if (i == kLeftFingerBaseLink || i == kRightFingerBaseLink) continue;
    EXPECT_NEAR(q[i], kInitialJointPositions[i], 2e-3) << "joint " << i;
  }
}

TEST(KukaSceneTest, MotorsRespectTheirVelocityLimit) {
  // Kuka.applyAction's arm motors: kp 0.3, at most 0.35 rad/s.
  KukaScene scene;
  scene.AddArm();
  scene.SetMotor(0, MotorCommand{.target = 1.5, .force = 200, .kp = 0.3, .max_velocity = 0.35});
  double fastest = 0;
  for (int i = 0; i < 240; ++i) {
    scene.StepSimulation();
    fastest = std::max(fastest, std::abs(scene.joint_velocities()[0]));
  }
  EXPECT_NEAR(fastest, 0.35, 0.01);
  EXPECT_NEAR(scene.joint_positions()[0], kInitialJointPositions[0] + 0.35, 0.02);
  EXPECT_THROW(scene.SetMotor(kLeftFingerBaseLink, MotorCommand{}), std::invalid_argument);
}

TEST(KukaSceneTest, DroppedObjectsComeToRestOnTheTrayFloor) {
  KukaScene scene;
  const ObjectShape a = GenerateObject(1);
  const ObjectShape b = GenerateObject(2);
  scene.AddObject(a, Eigen::Vector3d(0.6, 0.05, 0.15), 2.0);
  scene.AddObject(b, Eigen::Vector3d(0.5, -0.1, 0.15), 0.3);
  for (int i = 0; i < 600; ++i) scene.StepSimulation();
  EXPECT_TRUE(scene.ObjectsAtRest(2e-3, 2e-2));
  for (int i = 0; i < scene.num_objects(); ++i) {
    const Eigen::Vector3d p = scene.ObjectPose(i).translation();
    EXPECT_GT(p.x(), KukaScene::kTrayMinX);
    EXPECT_LT(p.x(), KukaScene::kTrayMaxX);
    EXPECT_GT(p.y(), KukaScene::kTrayMinY);
    EXPECT_LT(p.y(), KukaScene::kTrayMaxY);
    EXPECT_GT(p.z(), KukaScene::kTrayFloorZ);
    EXPECT_LT(p.z(), KukaScene::kTrayFloorZ + 0.05);
  }
  EXPECT_EQ(scene.num_steps(), 600);
}

TEST(KukaSceneTest, DrawItemsCoverTheSceneByGroup) {
  KukaScene scene;
  const ObjectShape a = GenerateObject(3);
  scene.AddObject(a, Eigen::Vector3d(0.6, 0.05, 0.15), 2.0);
  std::vector<DrawItem> items;
  scene.CollectDrawItems(&items);
  int arm_items = 0;
  for (const DrawItem& item : items) arm_items += item.group == DrawGroup::kArm ? 1 : 0;
  EXPECT_EQ(arm_items, 0);  // No arm yet.
  scene.AddArm();
  scene.CollectDrawItems(&items);
  int counts[4] = {};
  for (const DrawItem& item : items) ++counts[static_cast<int>(item.group)];
  EXPECT_EQ(counts[static_cast<int>(DrawGroup::kStatic)], 2 + 5);  // Ground, table, tray pieces.
  EXPECT_EQ(counts[static_cast<int>(DrawGroup::kObject)], static_cast<int>(a.parts.size()));
  EXPECT_GT(counts[static_cast<int>(DrawGroup::kArm)], 10);
  EXPECT_EQ(counts[static_cast<int>(DrawGroup::kGripper)], 7);
}

}  // namespace
}  // namespace rl::envs::kuka
