#include "envs/kuka/kuka_model.h"

#include <numbers>

namespace rl::envs::kuka {
namespace {

// SDF diffuse colours (spec 4.5).
constexpr std::array<float, 3> kDarkGrey = {0.2f, 0.2f, 0.2f};
constexpr std::array<float, 3> kBlue = {0.5f, 0.7f, 1.0f};
constexpr std::array<float, 3> kOrange = {1.0f, 0.4235f, 0.0392f};
constexpr std::array<float, 3> kGrey = {0.6f, 0.6f, 0.6f};

// Angles as the SDF writes them (not exactly pi/2 and pi).
constexpr double kHalfPi = 1.5708;
constexpr double kPi = 3.14159;

Shape Box(const Eigen::Vector3d& half_extents, const Eigen::Vector3d& centre) {
  Shape s;
  s.kind = Shape::Kind::kBox;
  s.size = half_extents;
  s.pose.translation() = centre;
  return s;
}

// A cylinder of `radius` and `half_length` centred at `centre` with its axis along the link
// frame's `axis` (0 = x, 1 = y, 2 = z).
Shape Cylinder(double radius, double half_length, const Eigen::Vector3d& centre, int axis) {
  Shape s;
  s.kind = Shape::Kind::kCylinder;
  s.size = Eigen::Vector3d(radius, radius, half_length);
  s.pose.translation() = centre;
  if (axis == 0)
    s.pose.linear() = Eigen::AngleAxisd(std::numbers::pi / 2, Eigen::Vector3d::UnitY()).matrix();
  if (axis == 1)
    s.pose.linear() = Eigen::AngleAxisd(-std::numbers::pi / 2, Eigen::Vector3d::UnitX()).matrix();
  return s;
}

Shape Sphere(double radius, const Eigen::Vector3d& centre) {
  Shape s;
  s.kind = Shape::Kind::kSphere;
  s.size = Eigen::Vector3d::Constant(radius);
  s.pose.translation() = centre;
  return s;
}

// An arm joint J0..J6: revolute about the link's z axis, limits +-limit, damping 0.5.
LinkSpec ArmLink(std::string_view name, int parent, double z, const Eigen::Vector3d& rpy,
                 double limit, double mass, const Eigen::Vector3d& com,
                 const std::array<float, 3>& color, std::vector<Shape> shapes) {
  LinkSpec l;
  l.name = name;
  l.parent = parent;
  l.position = Eigen::Vector3d(0, 0, z);
  l.rpy = rpy;
  l.revolute = true;
  l.axis = Eigen::Vector3d::UnitZ();
  l.limited = true;
  l.lower = -limit;
  l.upper = limit;
  l.damping = 0.5;
  l.mass = mass;
  l.com = com;
  l.color = color;
  l.shapes = std::move(shapes);
  return l;
}

// A finger link of the gripper. `joint_axis_y` false makes it a fixed link.
LinkSpec FingerLink(std::string_view name, int parent, const Eigen::Vector3d& position,
                    double pitch, bool revolute, double lower, double upper,
                    const Eigen::Vector3d& com, bool has_contact_tag, Shape shape) {
  LinkSpec l;
  l.name = name;
  l.parent = parent;
  l.position = position;
  l.rpy = Eigen::Vector3d(0, pitch, 0);
  l.revolute = revolute;
  l.axis = Eigen::Vector3d::UnitY();
  l.limited = revolute;
  l.lower = lower;
  l.upper = upper;
  l.mass = 0.2;
  l.com = com;
  if (has_contact_tag) {
    l.lateral_friction = 0.8;
    l.spinning_friction = 0.1;
  }
  l.color = kGrey;
  l.shapes = {shape};
  return l;
}

Eigen::Isometry3d PoseOf(const LinkSpec& l) {
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.translation() = l.position;
  t.linear() = RpyToMatrix(l.rpy);
  return t;
}

KukaModel BuildModel() {
  using V = Eigen::Vector3d;
  KukaModel m;

  // Base lbr_iiwa_link_0: fixed, frame at the world origin.
  m.base.name = "lbr_iiwa_link_0";
  m.base.com = V(-0.1, 0, 0.07);
  m.base.color = kDarkGrey;
  m.base.shapes = {Cylinder(0.12, 0.079, V(-0.0075, 0, 0.079), 2)};

  // Arm links lbr_iiwa_link_1..7 (PyBullet links 0..6). Shapes follow the mesh bounds: a
  // cylinder along the segment and a sphere or cylinder over the next joint.
  m.links[0] =
      ArmLink("lbr_iiwa_link_1", -1, 0.1575, V(0, 0, 0), 2.96706, 4, V(0, -0.03, 0.12), kBlue,
              {Cylinder(0.08, 0.10625, V(0, 0, 0.09625), 2), Sphere(0.086, V(0, -0.03, 0.2025))});
  m.links[1] =
      ArmLink("lbr_iiwa_link_2", 0, 0.36, V(kHalfPi, 0, -kPi), 2.0944, 4, V(0.0003, 0.059, 0.042),
              kBlue, {Sphere(0.085, V(0, 0, 0.03)), Cylinder(0.068, 0.10225, V(0, 0.10225, 0), 1)});
  m.links[2] =
      ArmLink("lbr_iiwa_link_3", 1, 0.5645, V(0, 0, 0), 2.96706, 3, V(0, 0.03, 0.13), kOrange,
              {Cylinder(0.068, 0.11275, V(0, 0, 0.10275), 2), Sphere(0.068, V(0, 0.047, 0.2155))});
  m.links[3] =
      ArmLink("lbr_iiwa_link_4", 2, 0.78, V(kHalfPi, 0, 0), 2.0944, 2.7, V(0, 0.067, 0.034), kBlue,
              {Cylinder(0.068, 0.09225, V(0, 0.09225, 0), 1), Sphere(0.068, V(0, 0, 0.046))});
  m.links[4] = ArmLink(
      "lbr_iiwa_link_5", 3, 0.9645, V(0, 0, -kPi), 2.96706, 1.7, V(0.0001, 0.021, 0.076), kBlue,
      {Cylinder(0.068, 0.11275, V(0, 0, 0.10275), 2), Sphere(0.068, V(0, 0.031, 0.199))});
  m.links[5] =
      ArmLink("lbr_iiwa_link_6", 4, 1.18, V(kHalfPi, 0, -kPi), 2.0944, 1.8, V(0, 0.0006, 0.0004),
              kOrange, {Cylinder(0.066, 0.0835, V(0, -0.0025, 0), 1)});
  m.links[6] = ArmLink("lbr_iiwa_link_7", 5, 1.261, V(0, 0, 0), 3.05433, 1.3, V(0, 0, 0.02), kGrey,
                       {Cylinder(0.052, 0.0275, V(0, 0, 0.0175), 2)});

  // Gripper base_link: continuous yaw joint (no limits, no damping), a 0.05 x 0.05 x 0.1 box.
  LinkSpec& g = m.links[kGripperYawJoint];
  g.name = "base_link";
  g.parent = kEndEffectorLink;
  g.position = V(0, 0, 1.305);
  g.revolute = true;
  g.axis = V::UnitZ();
  g.mass = 0.2;
  g.color = kGrey;
  g.shapes = {Box(V(0.025, 0.025, 0.05), V(0, 0, 0))};

  // Fingers: finger link (revolute about y, box 0.01 x 0.01 x 0.08), finger base (fixed), tip
  // (revolute about y). The right side mirrors the left in x. The left finger link has no
  // <contact> tag in the SDF, so it keeps the default friction.
  m.links[8] = FingerLink("left_finger", kGripperYawJoint, V(0, 0.024, 1.35), -0.05, true, -10.4,
                          10.01, V(0, 0, 0.04), false, Box(V(0.005, 0.005, 0.04), V(0, 0, 0.04)));
  m.links[9] =
      FingerLink("left_finger_base", 8, V(-0.005, 0.024, 1.43), -0.3, false, 0, 0,
                 V(-0.003, 0, 0.04), true, Box(V(0.019, 0.011, 0.038), V(-0.007, -0.002, 0.033)));
  m.links[10] = FingerLink("left_finger_tip", 9, V(-0.02, 0.024, 1.49), 0.2, true, -10.1, 10.3,
                           V(-0.005, 0, 0.026), true,
                           Box(V(0.012, 0.0095, 0.0255), V(-0.005, -0.0025, 0.0255)));
  m.links[11] = FingerLink("right_finger", kGripperYawJoint, V(0, 0.024, 1.35), 0.05, true, -10.01,
                           10.4, V(0, 0, 0.04), true, Box(V(0.005, 0.005, 0.04), V(0, 0, 0.04)));
  m.links[12] =
      FingerLink("right_finger_base", 11, V(0.005, 0.024, 1.43), 0.3, false, 0, 0,
                 V(0.003, 0, 0.04), true, Box(V(0.019, 0.011, 0.038), V(0.007, -0.002, 0.033)));
  m.links[13] = FingerLink("right_finger_tip", 12, V(0.02, 0.024, 1.49), -0.2, true, -10.3, 10.1,
                           V(0.005, 0, 0.026), true,
                           Box(V(0.012, 0.0095, 0.0255), V(0.005, -0.0025, 0.0255)));

  // Zero-configuration transforms from each parent frame to its child frame.
  for (int i = 0; i < kNumLinks; ++i) {
    const LinkSpec& l = m.links[i];
    const Eigen::Isometry3d parent_pose = l.parent < 0 ? PoseOf(m.base) : PoseOf(m.links[l.parent]);
    m.parent_to_link[i] = parent_pose.inverse() * PoseOf(l);
  }
  return m;
}

}  // namespace

Eigen::Matrix3d RpyToMatrix(const Eigen::Vector3d& rpy) {
  return (Eigen::AngleAxisd(rpy.z(), Eigen::Vector3d::UnitZ()) *
          Eigen::AngleAxisd(rpy.y(), Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(rpy.x(), Eigen::Vector3d::UnitX()))
      .matrix();
}

const KukaModel& Model() {
  static const KukaModel model = BuildModel();
  return model;
}

}  // namespace rl::envs::kuka
