#include "envs/kuka/kuka_diverse_object_env.h"

#include <algorithm>
#include <cmath>
#include <memory>
#include <numbers>
#include <stdexcept>
#include <string>

#include "common/check.h"
#include "envs/env_list.h"
#include "envs/kuka/kuka_kinematics.h"
#include "envs/kuka/kuka_renderer.h"
#include "envs/render_args.h"
#include "envs/rng.h"
#include "envs/specs.h"

namespace rl::envs {
namespace {

using kuka::KukaScene;
using kuka::MotorCommand;

// Kuka class constants (spec 4.4).
constexpr double kMaxForce = 200;         // Arm joints and gripper yaw, N m.
constexpr double kMaxVelocity = 0.35;     // Arm joints, rad/s.
constexpr double kArmPositionGain = 0.3;  // Arm joints; the others use the default 0.1.
constexpr double kFingerAForce = 2;       // Left finger (joint 8).
constexpr double kFingerBForce = 2.5;     // Right finger (joint 11).
constexpr double kFingerTipForce = 2;     // Tips (joints 10 and 13).
const Eigen::Vector3d kInitialTarget(0.537, 0.0, 0.5);
// Object drop height (m) and the rest test of settle_until_rest.
constexpr double kDropHeight = 0.15;
constexpr double kRestSpeed = 2e-3;         // m/s.
constexpr double kRestAngularSpeed = 2e-2;  // rad/s.
constexpr int kRestSteps = 24;              // 0.1 s at 240 Hz.

// (dx, dy, da) of the seven discrete actions, in units of dv and kGraspAngle (spec 4.8).
constexpr int kActionTable[KukaDiverseObjectEnv::kNumActions][3] = {
    {0, 0, 0}, {-1, 0, 0}, {1, 0, 0}, {0, -1, 0}, {0, 1, 0}, {0, 0, -1}, {0, 0, 1}};

void CheckFiniteNonNegative(double value, const char* name) {
  if (!std::isfinite(value) || value < 0) {
    throw std::invalid_argument(std::string("KukaDiverseObjectConfig: ") + name +
                                " must be finite and >= 0, got " + std::to_string(value));
  }
}

}  // namespace

void KukaDiverseObjectConfig::Validate() const {
  auto require = [](bool ok, const std::string& what) {
    if (!ok) throw std::invalid_argument("KukaDiverseObjectConfig: " + what);
  };
  require(num_objects >= 1 && num_objects <= 20,
          "num_objects must be in [1, 20], got " + std::to_string(num_objects));
  require(max_steps > 0, "max_steps must be positive, got " + std::to_string(max_steps));
  require(action_repeat > 0,
          "action_repeat must be positive, got " + std::to_string(action_repeat));
  require(solver_iterations > 0,
          "solver_iterations must be positive, got " + std::to_string(solver_iterations));
  require(settle_steps >= 0, "settle_steps must be >= 0, got " + std::to_string(settle_steps));
  require(width >= 1 && width <= 4096 && height >= 1 && height <= 4096,
          "width and height must be in [1, 4096], got " + std::to_string(width) + "x" +
              std::to_string(height));
  CheckFiniteNonNegative(dv, "dv");
  CheckFiniteNonNegative(block_random, "block_random");
  CheckFiniteNonNegative(camera_random, "camera_random");
}

KukaDiverseObjectEnv::KukaDiverseObjectEnv(const KukaDiverseObjectConfig& config)
    : SeededEnv(
          KukaDiverseObjectSpec(config.is_test, config.max_steps, config.width, config.height)),
      config_(config) {
  config_.Validate();
  RL_CHECK(spec().observation_size == static_cast<int>(observation_.size()) &&
           spec().num_actions == kNumActions)
      << "KukaDiverseObjectSpec() disagrees with the env";
  pool_ = kuka::ObjectIds(config_.is_test);
  shapes_.resize(kuka::kNumObjectIds);
  scene_ = std::make_unique<KukaScene>();
}

KukaDiverseObjectEnv::~KukaDiverseObjectEnv() = default;

const kuka::ObjectShape& KukaDiverseObjectEnv::Shape(int id) {
  if (!shapes_[id]) shapes_[id] = std::make_unique<kuka::ObjectShape>(kuka::GenerateObject(id));
  return *shapes_[id];
}

void KukaDiverseObjectEnv::NewEpisode() {
  // Camera: pitch, yaw, fov, in this order (spec 4.6).
  const double r = config_.camera_random;
  camera_ = kuka::CameraParams{};
  camera_.pitch = -56 + r * UniformDouble(rng(), -3, 3);
  camera_.yaw = 245 + r * UniformDouble(rng(), -3, 3);
  camera_.fov = 20 + r * UniformDouble(rng(), -2, 2);

  // Objects, with replacement, then their drop poses (spec 4.7).
  object_ids_.clear();
  for (int i = 0; i < config_.num_objects; ++i) {
    object_ids_.push_back(pool_[UniformInt(rng(), 0, static_cast<int64_t>(pool_.size()))]);
  }
  std::vector<Eigen::Vector3d> positions;
  std::vector<double> yaws;
  const double b = config_.block_random;
  for (int i = 0; i < config_.num_objects; ++i) {
    const double x = 0.4 + b * UniformDouble(rng(), 0, 1);
    const double y = b * (UniformDouble(rng(), 0, 1) - 0.5);
    yaws.push_back(std::numbers::pi / 2 + b * std::numbers::pi * UniformDouble(rng(), 0, 1));
    positions.emplace_back(x, y, kDropHeight);
  }

  // World, objects dropped one at a time and settled (the arm joins afterwards, see the header).
  scene_->Reset();
  scene_->set_solver_iterations(config_.solver_iterations);
  for (int i = 0; i < config_.num_objects; ++i) {
    scene_->AddObject(Shape(object_ids_[i]), positions[i], yaws[i]);
    int resting = 0;
    for (int step = 0; step < config_.settle_steps; ++step) {
      scene_->StepSimulation();
      if (!config_.settle_until_rest) continue;
      resting = scene_->ObjectsAtRest(kRestSpeed, kRestAngularSpeed) ? resting + 1 : 0;
      if (resting >= kRestSteps) break;
    }
    // Resting objects sleep until the next drop or the gripper wakes them.
    if (config_.settle_until_rest) scene_->PutRestingObjectsToSleep(kRestSpeed, kRestAngularSpeed);
  }
  scene_->AddArm(config_.rigid_fingertips);
  // The reference steps once after loading the arm.
  scene_->StepSimulation();

  end_effector_target_ = kInitialTarget;
  gripper_angle_target_ = 0;
  attempted_grasp_ = false;
  UpdateObservation();
}

void KukaDiverseObjectEnv::ApplyArmAction(double dx, double dy, double dz, double da,
                                          double finger_angle) {
  // Move the target within the workspace (z is not clamped) and turn the gripper.
  end_effector_target_.x() = std::clamp(end_effector_target_.x() + dx, kMinX, kMaxX);
  end_effector_target_.y() = std::clamp(end_effector_target_.y() + dy, kMinY, kMaxY);
  end_effector_target_.z() += dz;
  gripper_angle_target_ += da;

  // IK for lbr_iiwa_link_7 pointing down, from the current joint positions.
  const kuka::IkResult ik = kuka::SolveIk(end_effector_target_, kuka::GripperDownOrientation(),
                                          scene_->arm_joint_positions());
  for (int j = 0; j < kuka::kNumArmJoints; ++j) {
    scene_->SetMotor(j, MotorCommand{.target = ik.q[j],
                                     .force = kMaxForce,
                                     .kp = kArmPositionGain,
                                     .kd = 1.0,
                                     .max_velocity = kMaxVelocity});
  }
  scene_->SetMotor(kuka::kGripperYawJoint,
                   MotorCommand{.target = gripper_angle_target_, .force = kMaxForce});
  scene_->SetMotor(kuka::kLeftFingerJoint,
                   MotorCommand{.target = -finger_angle, .force = kFingerAForce});
  scene_->SetMotor(kuka::kRightFingerJoint,
                   MotorCommand{.target = finger_angle, .force = kFingerBForce});
  if (!config_.rigid_fingertips) {
    scene_->SetMotor(kuka::kLeftTipJoint, MotorCommand{.target = 0, .force = kFingerTipForce});
    scene_->SetMotor(kuka::kRightTipJoint, MotorCommand{.target = 0, .force = kFingerTipForce});
  }
}

StepResult KukaDiverseObjectEnv::OnStep(std::span<const float> action_floats) {
  // Move: every action also descends by dv (the reference's height hack).
  const int action = ActionIndex(action_floats);
  const double dv = config_.dv;
  ApplyArmAction(dv * kActionTable[action][0], dv * kActionTable[action][1], -dv,
                 kGraspAngle * kActionTable[action][2], kFingerOpen);
  for (int i = 0; i < config_.action_repeat; ++i) {
    scene_->StepSimulation();
    if (attempted_grasp_ || elapsed_steps() >= config_.max_steps) break;
  }

  // Grasp once lbr_iiwa_link_7's centre of mass is low enough: close for 500 steps, then lift
  // the target by 1 mm a step for 500 steps, the fingers' target closing by 0.003 rad a step.
  if (scene_->LinkCenterOfMass(kuka::kEndEffectorLink).z() <= kGraspTriggerHeight) {
    double finger_angle = kFingerOpen;
    for (int i = 0; i < kGraspCloseSteps; ++i) {
      ApplyArmAction(0, 0, 0, 0, finger_angle);
      scene_->StepSimulation();
      finger_angle = std::max(finger_angle - kFingerOpen / 100, 0.0);
    }
    for (int i = 0; i < kGraspLiftSteps; ++i) {
      ApplyArmAction(0, 0, 0.001, 0, finger_angle);
      scene_->StepSimulation();
      finger_angle = std::max(finger_angle - kFingerOpen / 100, 0.0);
    }
    attempted_grasp_ = true;
  }

  StepResult result;
  result.reward = ObjectLifted() ? 1.0 : 0.0;
  result.terminated = attempted_grasp_ || elapsed_steps() >= config_.max_steps;
  UpdateObservation();
  return result;
}

bool KukaDiverseObjectEnv::ObjectLifted() const {
  for (int i = 0; i < scene_->num_objects(); ++i) {
    if (scene_->ObjectPose(i).translation().z() > kSuccessHeight) return true;
  }
  return false;
}

Eigen::Vector3d KukaDiverseObjectEnv::GraspPoint() const {
  const kuka::KukaModel& m = kuka::Model();
  const Eigen::Vector3d left = scene_->LinkFrame(kuka::kLeftTipJoint) *
                               m.links[kuka::kLeftTipJoint].shapes[0].pose.translation();
  const Eigen::Vector3d right = scene_->LinkFrame(kuka::kRightTipJoint) *
                                m.links[kuka::kRightTipJoint].shapes[0].pose.translation();
  return (left + right) / 2;
}

void KukaDiverseObjectEnv::UpdateObservation() {
  // The step index: Steps since Reset (0 while the episode starts).
  const int64_t step = elapsed_steps();
  observation_[0] = static_cast<float>(step);
  observation_[1] = static_cast<float>(static_cast<double>(step) / config_.max_steps);
}

void KukaDiverseObjectEnv::Render(std::vector<uint8_t>* rgb, int* width, int* height) const {
  RenderNative(*this, config_.width, config_.height, rgb, width, height);
}

void KukaDiverseObjectEnv::RenderSized(int width, int height, std::vector<uint8_t>* rgb) const {
  CheckRenderArgs(*this, "KukaDiverseObjectEnv", width, height, rgb);
  if (!renderer_) renderer_ = std::make_unique<kuka::KukaRenderer>();
  scene_->CollectDrawItems(&draw_items_);
  renderer_->Render(camera_, draw_items_, width, height, rgb);
}

// Registered as KukaDiverseObjectGrasping-v0 (the training objects, 15 steps) and
// KukaDiverseObjectGraspingTest-v0 (the held-out objects, the 20 steps of evaluation) in
// env_list.inc. An episode also ends at its grasp attempt.
std::unique_ptr<Env> MakeKukaDiverseObjectGraspingV0(const EnvIdParts&) {
  return std::make_unique<KukaDiverseObjectEnv>();
}

std::unique_ptr<Env> MakeKukaDiverseObjectGraspingTestV0(const EnvIdParts&) {
  return std::make_unique<KukaDiverseObjectEnv>(
      KukaDiverseObjectConfig{.is_test = true, .max_steps = 20});
}

}  // namespace rl::envs
