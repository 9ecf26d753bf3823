#include "envs/kuka/kuka_scene.h"

#include <algorithm>
#include <array>
#include <cstddef>
#include <stdexcept>
#include <string>
#include <utility>

#include <BulletDynamics/Featherstone/btMultiBody.h>
#include <BulletDynamics/Featherstone/btMultiBodyConstraintSolver.h>
#include <BulletDynamics/Featherstone/btMultiBodyDynamicsWorld.h>
#include <BulletDynamics/Featherstone/btMultiBodyJointMotor.h>
#include <BulletDynamics/Featherstone/btMultiBodyLinkCollider.h>
#include <btBulletDynamicsCommon.h>

#include "common/check.h"

namespace rl::envs::kuka {
namespace {

// Collision margin of every shape: PyBullet's mesh margin (spec 4.2).
constexpr double kMargin = 0.001;
// Friction of the static bodies (plane.urdf and table.urdf 1.0, tray.urdf 0.5) and the damping
// that PyBullet's single-link bodies get by default.
constexpr double kPlaneFriction = 1.0;
constexpr double kTableFriction = 1.0;
constexpr double kTrayFriction = 0.5;
constexpr double kObjectDamping = 0.04;
// Rolling resistance of the objects (a lever of 5 mm; the reference URDFs say 0). Without it the
// rounded generated hulls rock or wobble on Bullet's contacts for many seconds instead of coming
// to rest, so the tray never settles.
constexpr double kObjectRollingFriction = 0.005;
// Objects' inertia is the bounding-box approximation times the URDFs' inertia_scaling.
constexpr double kObjectInertiaScaling = 3.0;
// Kuka.reset(): every joint holds its initial position with this force.
constexpr double kResetMotorForce = 200;

// Drawing colours (approximations of the textures of the reference).
constexpr std::array<float, 3> kPlaneColor = {0.45f, 0.45f, 0.45f};
constexpr std::array<float, 3> kTableColor = {0.72f, 0.58f, 0.42f};

btVector3 ToBt(const Eigen::Vector3d& v) { return {v.x(), v.y(), v.z()}; }
Eigen::Vector3d ToEigen(const btVector3& v) { return {v.x(), v.y(), v.z()}; }

btQuaternion ToBtQuaternion(const Eigen::Matrix3d& r) {
  const Eigen::Quaterniond q(r);
  return {q.x(), q.y(), q.z(), q.w()};
}

btTransform ToBt(const Eigen::Isometry3d& t) {
  btTransform b;
  b.setOrigin(ToBt(Eigen::Vector3d(t.translation())));
  b.setRotation(ToBtQuaternion(t.linear()));
  return b;
}

Eigen::Isometry3d ToEigen(const btTransform& b) {
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.translation() = ToEigen(b.getOrigin());
  const btQuaternion q = b.getRotation();
  t.linear() = Eigen::Quaterniond(q.w(), q.x(), q.y(), q.z()).toRotationMatrix();
  return t;
}

// The tray (tray.urdf scaled 0.5, rotated by pi about z, spec 4.3) as convex hulls in the world:
// the base plate (first, an axis-aligned box) and four sloped walls from the plate's edge up to the
// rim. The reference mesh's fifth piece (a ridge inside the tray, marked unconfirmed in the spec)
// is left out.
std::vector<ConvexHull> TrayParts() {
  // Tray-local coordinates to world: x -> 0.64 - x, y -> 0.075 - y, z -> -0.19 + z.
  auto w = [](double x, double y, double z) {
    return Eigen::Vector3d(0.64 - x, 0.075 - y, -0.19 + z);
  };
  const double fx = 0.2088, fy0 = -0.2077, fy1 = 0.2333, fz = 0.005;  // Plate.
  const double rx = 0.297, ry0 = -0.295, ry1 = 0.320, rz = 0.133;     // Outer rim.
  std::vector<std::vector<Eigen::Vector3d>> pieces;
  std::vector<Eigen::Vector3d> plate;
  for (double x : {-fx, fx}) {
    for (double y : {fy0, fy1}) {
      for (double z : {-fz, fz}) plate.push_back(w(x, y, z));
    }
  }
  pieces.push_back(plate);
  // Walls along y at x = +-: a wedge whose inner face rises from the plate edge to the rim.
  for (double s : {-1.0, 1.0}) {
    std::vector<Eigen::Vector3d> wall;
    for (double y : {ry0, ry1}) {
      wall.push_back(w(s * fx, y, -fz));
      wall.push_back(w(s * rx, y, -fz));
      wall.push_back(w(s * rx, y, rz));
    }
    pieces.push_back(wall);
  }
  // Walls along x at the two y edges.
  for (const auto& [edge, rim] : {std::pair{fy0, ry0}, std::pair{fy1, ry1}}) {
    std::vector<Eigen::Vector3d> wall;
    for (double x : {-rx, rx}) {
      wall.push_back(w(x, edge, -fz));
      wall.push_back(w(x, rim, -fz));
      wall.push_back(w(x, rim, rz));
    }
    pieces.push_back(wall);
  }
  std::vector<ConvexHull> parts;
  for (const auto& p : pieces) parts.push_back(ComputeConvexHull(p));
  return parts;
}

// Affine transform that maps a unit primitive mesh onto `shape` in the link frame `link`.
Eigen::Affine3d PrimitiveTransform(const Eigen::Isometry3d& link, const Shape& shape) {
  return Eigen::Affine3d(link * shape.pose) * Eigen::Scaling(shape.size);
}

const Mesh& PrimitiveMesh(const Shape& shape) {
  switch (shape.kind) {
    case Shape::Kind::kBox:
      return UnitBoxMesh();
    case Shape::Kind::kCylinder:
      return UnitCylinderMesh();
    case Shape::Kind::kSphere:
      break;
  }
  return UnitSphereMesh();
}

}  // namespace

// Every Bullet object of one world. Bodies, constraints and the multibody are removed from the
// world before anything is deleted.
struct KukaScene::World {
  btDefaultCollisionConfiguration config;
  btCollisionDispatcher dispatcher{&config};
  btDbvtBroadphase broadphase;
  btMultiBodyConstraintSolver solver;
  btMultiBodyDynamicsWorld world{&dispatcher, &broadphase, &solver, &config};
  std::vector<std::unique_ptr<btCollisionShape>> shapes;
  std::vector<std::unique_ptr<btRigidBody>> statics;
  std::vector<std::unique_ptr<btRigidBody>> objects;
  std::unique_ptr<btMultiBody> arm;
  std::unique_ptr<btMultiBodyLinkCollider> base_collider;
  std::array<std::unique_ptr<btMultiBodyLinkCollider>, kNumLinks> colliders;
  std::array<std::unique_ptr<btMultiBodyJointMotor>, kNumLinks> motors;
  std::vector<ConvexHull> tray_parts;

  World() = default;
  World(const World&) = delete;
  World& operator=(const World&) = delete;
  ~World() {
    for (auto& m : motors) {
      if (m) world.removeMultiBodyConstraint(m.get());
    }
    for (auto& c : colliders) {
      if (c) world.removeCollisionObject(c.get());
    }
    if (base_collider) world.removeCollisionObject(base_collider.get());
    if (arm) world.removeMultiBody(arm.get());
    for (auto& b : objects) world.removeRigidBody(b.get());
    for (auto& b : statics) world.removeRigidBody(b.get());
  }

  // Takes ownership of a shape and returns it.
  template <typename T>
  T* Own(std::unique_ptr<T> shape) {
    T* raw = shape.get();
    shapes.push_back(std::move(shape));
    return raw;
  }

  // A convex hull shape of `hull`'s vertices with PyBullet's margin.
  btConvexHullShape* HullShape(const ConvexHull& hull) {
    auto shape = std::make_unique<btConvexHullShape>();
    for (const Eigen::Vector3d& v : hull.vertices) shape->addPoint(ToBt(v), false);
    shape->recalcLocalAabb();
    shape->setMargin(kMargin);
    return Own(std::move(shape));
  }

  // A static body with `shape` at `pose`.
  void AddStatic(btCollisionShape* shape, const btTransform& pose, double friction) {
    btRigidBody::btRigidBodyConstructionInfo info(0, nullptr, shape);
    info.m_startWorldTransform = pose;
    info.m_friction = friction;
    statics.push_back(std::make_unique<btRigidBody>(info));
    world.addRigidBody(statics.back().get());
  }

  // The compound collision shape of a link, in the link's centre-of-mass frame.
  btCompoundShape* LinkShape(const LinkSpec& link) {
    auto compound = std::make_unique<btCompoundShape>(false);
    Eigen::Isometry3d com_to_link = Eigen::Isometry3d::Identity();
    com_to_link.translation() = -link.com;
    for (const Shape& s : link.shapes) {
      std::unique_ptr<btCollisionShape> child;
      switch (s.kind) {
        case Shape::Kind::kBox:
          child = std::make_unique<btBoxShape>(ToBt(s.size));
          break;
        case Shape::Kind::kCylinder:
          child = std::make_unique<btCylinderShapeZ>(ToBt(s.size));
          break;
        case Shape::Kind::kSphere:
          child = std::make_unique<btSphereShape>(s.size.x());
          break;
      }
      if (s.kind != Shape::Kind::kSphere) child->setMargin(kMargin);
      compound->addChildShape(ToBt(com_to_link * s.pose), Own(std::move(child)));
    }
    return Own(std::move(compound));
  }

  // A collider for link `link` (-1: the base) of the arm.
  std::unique_ptr<btMultiBodyLinkCollider> Collider(int link, const LinkSpec& spec,
                                                    btCollisionShape* shape) {
    auto collider = std::make_unique<btMultiBodyLinkCollider>(arm.get(), link);
    collider->setCollisionShape(shape);
    collider->setFriction(spec.lateral_friction);
    collider->setSpinningFriction(spec.spinning_friction);
    return collider;
  }

  // The arm as a fixed-base multibody (spec 4.5), at the initial joint positions.
  void BuildArm(bool rigid_fingertips) {
    const KukaModel& m = Model();
    arm = std::make_unique<btMultiBody>(kNumLinks, 0, btVector3(0, 0, 0), /*fixedBase=*/true,
                                        /*canSleep=*/false);
    // Bullet's link frames sit at the centres of mass, oriented like the link frames.
    btTransform base_pose;
    base_pose.setIdentity();
    base_pose.setOrigin(ToBt(m.base.com));
    arm->setBaseWorldTransform(base_pose);
    std::array<btCollisionShape*, kNumLinks> link_shapes{};
    for (int i = 0; i < kNumLinks; ++i) {
      const LinkSpec& l = m.links[i];
      const bool welded = rigid_fingertips && (i == kLeftTipJoint || i == kRightTipJoint);
      link_shapes[i] = LinkShape(l);
      // PyBullet recomputes the inertia from the collision shape's bounding box.
      btVector3 inertia(0, 0, 0);
      link_shapes[i]->calculateLocalInertia(l.mass, inertia);
      const Eigen::Isometry3d& rel = m.parent_to_link[i];
      const Eigen::Vector3d parent_com = l.parent < 0 ? m.base.com : m.links[l.parent].com;
      const btQuaternion parent_to_this = ToBtQuaternion(rel.linear().transpose());
      const btVector3 parent_com_to_pivot = ToBt(Eigen::Vector3d(rel.translation() - parent_com));
      if (l.revolute && !welded) {
        arm->setupRevolute(i, l.mass, inertia, l.parent, parent_to_this, ToBt(l.axis),
                           parent_com_to_pivot, ToBt(l.com), true);
      } else {
        arm->setupFixed(i, l.mass, inertia, l.parent, parent_to_this, parent_com_to_pivot,
                        ToBt(l.com));
      }
    }
    arm->finalizeMultiDof();
    arm->setHasSelfCollision(false);
    for (int i = 0; i < kNumLinks; ++i) {
      if (arm->getLink(i).m_jointType == btMultibodyLink::eRevolute) {
        arm->setJointPos(i, kInitialJointPositions[i]);
        arm->setJointVel(i, 0);
      }
    }
    world.addMultiBody(arm.get());

    // Colliders: the fixed base is static; links collide with everything but one another.
    base_collider = Collider(-1, m.base, LinkShape(m.base));
    arm->setBaseCollider(base_collider.get());
    world.addCollisionObject(base_collider.get(), btBroadphaseProxy::StaticFilter,
                             btBroadphaseProxy::AllFilter ^ btBroadphaseProxy::StaticFilter);
    for (int i = 0; i < kNumLinks; ++i) {
      colliders[i] = Collider(i, m.links[i], link_shapes[i]);
      arm->getLink(i).m_collider = colliders[i].get();
      world.addCollisionObject(colliders[i].get(), btBroadphaseProxy::DefaultFilter,
                               btBroadphaseProxy::AllFilter);
    }

    // Motors on every revolute joint. Joint limits are not constraints here: SetMotor clamps
    // the targets into them (as PyBullet does), the motors' velocity limit keeps overshoot tiny,
    // and the task's workspace stays far from the arm's limits (the fingers' +-10 rad can never
    // be reached). Fourteen always-present limit rows would cost about 15% of every step.
    for (int i = 0; i < kNumLinks; ++i) {
      if (arm->getLink(i).m_jointType != btMultibodyLink::eRevolute) continue;
      motors[i] = std::make_unique<btMultiBodyJointMotor>(arm.get(), i, 0.0, 0.0);
      world.addMultiBodyConstraint(motors[i].get());
    }
    // Place the colliders at the initial pose.
    btAlignedObjectArray<btQuaternion> world_to_local;
    btAlignedObjectArray<btVector3> local_origin;
    arm->forwardKinematics(world_to_local, local_origin);
    arm->updateCollisionObjectWorldTransforms(world_to_local, local_origin);
  }
};

KukaScene::KukaScene() { Reset(); }

KukaScene::~KukaScene() = default;

void KukaScene::Reset() {
  objects_.clear();
  num_steps_ = 0;
  world_.reset();
  world_ = std::make_unique<World>();
  World& w = *world_;

  // Physics settings of the reference (spec 4.2).
  w.world.setGravity(btVector3(0, 0, kGravity));
  btContactSolverInfo& info = w.world.getSolverInfo();
  info.m_numIterations = kSolverIterations;
  info.m_erp2 = 0.08;
  info.m_frictionERP = 0.2;
  info.m_linearSlop = 1e-5;
  info.m_warmstartingFactor = 0.1;
  info.m_leastSquaresResidualThreshold = 1e-7;

  // Ground plane (top at z = -1) and table (top 1.5 x 1 at z = -0.195).
  btTransform pose;
  pose.setIdentity();
  w.AddStatic(w.Own(std::make_unique<btStaticPlaneShape>(btVector3(0, 0, 1), -1.0)), pose,
              kPlaneFriction);
  auto table = std::make_unique<btBoxShape>(btVector3(0.75, 0.5, 0.025));
  table->setMargin(kMargin);
  pose.setOrigin(btVector3(0.5, 0, -0.22));
  w.AddStatic(w.Own(std::move(table)), pose, kTableFriction);

  // Tray: one static body per piece (cheaper to collide with than one compound), each centred
  // on its piece; the base plate is a box.
  w.tray_parts = TrayParts();
  for (std::size_t i = 0; i < w.tray_parts.size(); ++i) {
    const ConvexHull& part = w.tray_parts[i];
    Eigen::Vector3d lo = part.vertices[0], hi = part.vertices[0];
    for (const Eigen::Vector3d& v : part.vertices) {
      lo = lo.cwiseMin(v);
      hi = hi.cwiseMax(v);
    }
    const Eigen::Vector3d centre = (lo + hi) / 2;
    pose.setIdentity();
    pose.setOrigin(ToBt(centre));
    if (i == 0) {
      auto plate = std::make_unique<btBoxShape>(ToBt(Eigen::Vector3d((hi - lo) / 2)));
      plate->setMargin(kMargin);
      w.AddStatic(w.Own(std::move(plate)), pose, kTrayFriction);
    } else {
      ConvexHull centred;
      for (const Eigen::Vector3d& v : part.vertices) centred.vertices.push_back(v - centre);
      w.AddStatic(w.HullShape(centred), pose, kTrayFriction);
    }
  }
}

void KukaScene::AddArm(bool rigid_fingertips) {
  RL_CHECK(!has_arm()) << "AddArm called twice after one Reset";
  world_->BuildArm(rigid_fingertips);
  // Kuka.reset(): every joint holds its initial position.
  for (int i = 0; i < kNumLinks; ++i) {
    if (!world_->motors[i]) continue;
    SetMotor(i, MotorCommand{.target = kInitialJointPositions[i], .force = kResetMotorForce});
  }
}

bool KukaScene::has_arm() const { return world_->arm != nullptr; }

bool KukaScene::ObjectsAtRest(double max_speed, double max_angular_speed) const {
  for (int i = 0; i < num_objects(); ++i) {
    if (ObjectSpeed(i) > max_speed || ObjectAngularSpeed(i) > max_angular_speed) return false;
  }
  return true;
}

int KukaScene::PutRestingObjectsToSleep(double max_speed, double max_angular_speed) {
  int sleeping = 0;
  for (auto& body : world_->objects) {
    if (body->getLinearVelocity().length() > max_speed ||
        body->getAngularVelocity().length() > max_angular_speed) {
      continue;
    }
    body->setLinearVelocity(btVector3(0, 0, 0));
    body->setAngularVelocity(btVector3(0, 0, 0));
    body->setActivationState(ISLAND_SLEEPING);
    ++sleeping;
  }
  return sleeping;
}

void KukaScene::AddObject(const ObjectShape& shape, const Eigen::Vector3d& position, double yaw) {
  World& w = *world_;
  auto compound = std::make_unique<btCompoundShape>(false);
  btTransform identity;
  identity.setIdentity();
  for (const ConvexHull& part : shape.parts) compound->addChildShape(identity, w.HullShape(part));
  btVector3 inertia(0, 0, 0);
  compound->calculateLocalInertia(shape.mass, inertia);
  btRigidBody::btRigidBodyConstructionInfo info(shape.mass, nullptr, w.Own(std::move(compound)),
                                                inertia * kObjectInertiaScaling);
  info.m_startWorldTransform.setIdentity();
  info.m_startWorldTransform.setOrigin(ToBt(position));
  info.m_startWorldTransform.setRotation(btQuaternion(btVector3(0, 0, 1), yaw));
  info.m_friction = shape.lateral_friction;
  info.m_rollingFriction = kObjectRollingFriction;
  info.m_spinningFriction = 0;
  info.m_linearDamping = kObjectDamping;
  info.m_angularDamping = kObjectDamping;
  w.objects.push_back(std::make_unique<btRigidBody>(info));
  w.world.addRigidBody(w.objects.back().get());
  objects_.push_back(&shape);
}

void KukaScene::set_solver_iterations(int iterations) {
  RL_CHECK(iterations > 0) << "solver iterations must be positive, got " << iterations;
  world_->world.getSolverInfo().m_numIterations = iterations;
}

void KukaScene::StepSimulation() {
  World& w = *world_;
  // Joint damping: a torque -damping * qdot on each joint, every step (PyBullet's step handler).
  const KukaModel& m = Model();
  if (w.arm) {
    for (int i = 0; i < kNumLinks; ++i) {
      if (m.links[i].damping > 0) {
        w.arm->addJointTorque(i, -m.links[i].damping * w.arm->getJointVel(i));
      }
    }
  }
  w.world.stepSimulation(kTimeStep, 0, kTimeStep);
  ++num_steps_;
}

void KukaScene::SetMotor(int joint, const MotorCommand& command) {
  RL_CHECK(has_arm()) << "SetMotor needs the arm (AddArm)";
  if (joint < 0 || joint >= kNumLinks || !world_->motors[joint]) {
    throw std::invalid_argument("KukaScene::SetMotor: joint " + std::to_string(joint) +
                                " is not a revolute joint");
  }
  const LinkSpec& l = Model().links[joint];
  double target = command.target;
  if (l.limited && l.lower <= l.upper) target = std::clamp(target, l.lower, l.upper);
  btMultiBodyJointMotor& motor = *world_->motors[joint];
  motor.setPositionTarget(target, command.kp);
  motor.setVelocityTarget(0, command.kd);
  motor.setMaxAppliedImpulse(command.force * kTimeStep);
  motor.setRhsClamp(command.max_velocity);
}

JointPositions KukaScene::joint_positions() const {
  RL_CHECK(has_arm()) << "no arm";
  JointPositions q{};
  for (int i = 0; i < kNumLinks; ++i) {
    if (world_->motors[i]) q[i] = world_->arm->getJointPos(i);
  }
  return q;
}

JointPositions KukaScene::joint_velocities() const {
  RL_CHECK(has_arm()) << "no arm";
  JointPositions v{};
  for (int i = 0; i < kNumLinks; ++i) {
    if (world_->motors[i]) v[i] = world_->arm->getJointVel(i);
  }
  return v;
}

ArmJoints KukaScene::arm_joint_positions() const {
  RL_CHECK(has_arm()) << "no arm";
  ArmJoints q;
  for (int i = 0; i < kNumArmJoints; ++i) q[i] = world_->arm->getJointPos(i);
  return q;
}

Eigen::Isometry3d KukaScene::LinkFrame(int link) const {
  RL_CHECK(has_arm() && link >= -1 && link < kNumLinks) << "no link " << link;
  const KukaModel& m = Model();
  const btMultiBodyLinkCollider* collider =
      link < 0 ? world_->base_collider.get() : world_->colliders[link].get();
  Eigen::Isometry3d com_frame = ToEigen(collider->getWorldTransform());
  return com_frame * Eigen::Translation3d(-(link < 0 ? m.base.com : m.links[link].com));
}

Eigen::Vector3d KukaScene::LinkCenterOfMass(int link) const {
  RL_CHECK(has_arm() && link >= -1 && link < kNumLinks) << "no link " << link;
  const btMultiBodyLinkCollider* collider =
      link < 0 ? world_->base_collider.get() : world_->colliders[link].get();
  return ToEigen(collider->getWorldTransform().getOrigin());
}

Eigen::Isometry3d KukaScene::ObjectPose(int i) const {
  RL_CHECK(i >= 0 && i < num_objects()) << "no object " << i;
  return ToEigen(world_->objects[i]->getWorldTransform());
}

double KukaScene::ObjectSpeed(int i) const {
  RL_CHECK(i >= 0 && i < num_objects()) << "no object " << i;
  return world_->objects[i]->getLinearVelocity().length();
}

double KukaScene::ObjectAngularSpeed(int i) const {
  RL_CHECK(i >= 0 && i < num_objects()) << "no object " << i;
  return world_->objects[i]->getAngularVelocity().length();
}

void KukaScene::CollectDrawItems(std::vector<DrawItem>* items) const {
  RL_CHECK(items != nullptr) << "CollectDrawItems needs an output vector";
  items->clear();
  const KukaModel& m = Model();
  const Eigen::Affine3d identity = Eigen::Affine3d::Identity();

  // Ground (a large slab under the table), table and tray.
  items->push_back(
      {&UnitBoxMesh(),
       Eigen::Translation3d(0.5, 0, -1.05) * Eigen::Scaling(Eigen::Vector3d(5, 5, 0.05)),
       kPlaneColor, DrawGroup::kStatic});
  items->push_back(
      {&UnitBoxMesh(),
       Eigen::Translation3d(0.5, 0, -0.22) * Eigen::Scaling(Eigen::Vector3d(0.75, 0.5, 0.025)),
       kTableColor, DrawGroup::kStatic});
  for (const ConvexHull& part : world_->tray_parts) {
    items->push_back({&part.mesh, identity, kTrayColor, DrawGroup::kStatic});
  }

  // Objects.
  for (int i = 0; i < num_objects(); ++i) {
    const Eigen::Affine3d pose(ObjectPose(i));
    for (const ConvexHull& part : objects_[i]->parts) {
      items->push_back({&part.mesh, pose, objects_[i]->color, DrawGroup::kObject});
    }
  }

  // Arm and gripper.
  if (!has_arm()) return;
  const Eigen::Isometry3d base = LinkFrame(-1);
  for (const Shape& s : m.base.shapes) {
    items->push_back(
        {&PrimitiveMesh(s), PrimitiveTransform(base, s), m.base.color, DrawGroup::kArm});
  }
  for (int i = 0; i < kNumLinks; ++i) {
    const Eigen::Isometry3d frame = LinkFrame(i);
    const DrawGroup group = i < kGripperYawJoint ? DrawGroup::kArm : DrawGroup::kGripper;
    for (const Shape& s : m.links[i].shapes) {
      items->push_back({&PrimitiveMesh(s), PrimitiveTransform(frame, s), m.links[i].color, group});
    }
  }
}

}  // namespace rl::envs::kuka
