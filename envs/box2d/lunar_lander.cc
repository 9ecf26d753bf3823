// LunarLander physics on Box2D 2.4.1.
//
// The reference runs pybox2d, whose embedded Box2D core is a 2.3 version. Where 2.4.1 differs:
//
// API (handled, no behavioural change intended):
// - Edges are built with b2EdgeShape::SetTwoSided (2.3's Set); the two-sided edge is what pybox2d
//   creates.
// - pybox2d fills b2RevoluteJointDef::referenceAngle with bodyB.angle - bodyA.angle when both
//   bodies are given; the C++ API never does, so it is set explicitly for each leg (+-0.05).
// - Bodies are told apart by pointer in the contact listener, so no user data is needed (2.4.1
//   declares b2Body::SetUserData but never defines it).
// - Fixture defaults are unchanged (friction 0.2, restitution 0, category 0x0001, mask 0xFFFF):
//   the moon's base edge and the legs keep friction 0.2 as in the reference. 2.3's global
//   restitution velocity threshold (1 m/s) became b2FixtureDef::restitutionThreshold with the same
//   default; all restitutions are 0 here anyway.
// - b2_maxPolygonVertices is 8 in 2.4.1 (16 in pybox2d); the lander's hull has 6.
//
// Behaviour (not reproducible with 2.4.1; trajectories diverge, the statistics agree):
// - The revolute joint solver was rewritten: 2.4 limits are speculative rather than stateful and
//   the motor, the limits and the point constraint are solved separately. The legs rest against
//   their limits during the whole flight and start outside them (the joints begin violated, as in
//   the reference, and the first world step inside Reset snaps the legs into place), so the legs
//   move slightly differently, most visibly at touchdown.
// - Edge-versus-polygon collision was rewritten, so contact points and normals on the terrain,
//   and hence touchdowns, differ slightly.
// - The broad phase no longer sorts new pairs (contacts are solved in another order), gravity is
//   integrated as v += h * invMass * (mass * g + F) (rounding only), and the island code sets the
//   awake flag directly (sleep timing of woken bodies may differ by a step).
// - Damping formulas and hull welding changed too, without effect here (no damping, no near-
//   duplicate vertices).
// The tests therefore check the reference's documented scores (heuristic and random policies)
// rather than its trajectories.
#include "envs/box2d/lunar_lander.h"

#include <box2d/box2d.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <numbers>
#include <stdexcept>
#include <string>
#include <utility>

#include "common/check.h"
#include "envs/env_list.h"
#include "envs/rng.h"
#include "envs/specs.h"

namespace rl::envs {
namespace {

// The lander's hull in pixels (divided by kScale for metres).
constexpr std::array<std::array<double, 2>, 6> kLanderPoly = {
    {{-14, +17}, {-17, 0}, {-17, -10}, {+17, -10}, {+17, 0}, {+14, +17}}};

// Collision filtering: lander and legs collide with the moon only, never with each other.
constexpr uint16_t kMoonCategory = 0x0001;
constexpr uint16_t kLanderCategory = 0x0010;
constexpr uint16_t kLegCategory = 0x0020;

// Fuel cost per step at full throttle.
constexpr double kMainEngineCost = 0.30;
constexpr double kSideEngineCost = 0.03;

b2Vec2 ToVec2(double x, double y) { return b2Vec2(static_cast<float>(x), static_cast<float>(y)); }

}  // namespace

// The Box2D world of one episode: the bodies and the contact flags, which Box2D sets through the
// listener callbacks at the start of each world step.
struct LunarLander::Physics final : public b2ContactListener {
  explicit Physics(double gravity) : world(ToVec2(0, gravity)) { world.SetContactListener(this); }
  // The listener is removed before the bodies are destroyed, as the reference does.
  ~Physics() override { world.SetContactListener(nullptr); }
  Physics(const Physics&) = delete;
  Physics& operator=(const Physics&) = delete;

  // A contact between the lander's body and the moon is a crash; a leg's contact sets its flag.
  void BeginContact(b2Contact* contact) override {
    const b2Body* a = contact->GetFixtureA()->GetBody();
    const b2Body* b = contact->GetFixtureB()->GetBody();
    if (a == lander || b == lander) game_over = true;
    for (int i = 0; i < 2; ++i) {
      if (a == legs[i] || b == legs[i]) ground_contact[i] = true;
    }
  }
  // Any contact of a leg that ends clears its flag (even if another one persists).
  void EndContact(b2Contact* contact) override {
    const b2Body* a = contact->GetFixtureA()->GetBody();
    const b2Body* b = contact->GetFixtureB()->GetBody();
    for (int i = 0; i < 2; ++i) {
      if (a == legs[i] || b == legs[i]) ground_contact[i] = false;
    }
  }

  b2World world;
  b2Body* moon = nullptr;
  b2Body* lander = nullptr;
  std::array<b2Body*, 2> legs{};  // legs[0] is on the +x side (i = -1), legs[1] on the -x side.
  std::array<b2RevoluteJoint*, 2> joints{};
  bool game_over = false;
  std::array<bool, 2> ground_contact{};
};

void LunarLanderConfig::Validate() const {
  if (!(gravity > -12.0 && gravity < 0.0)) {
    throw std::invalid_argument("LunarLanderConfig: gravity must lie in (-12, 0), got " +
                                std::to_string(gravity));
  }
  if (!std::isfinite(wind_power) || !std::isfinite(turbulence_power)) {
    throw std::invalid_argument(
        "LunarLanderConfig: wind_power and turbulence_power must be finite, got " +
        std::to_string(wind_power) + " and " + std::to_string(turbulence_power));
  }
}

LunarLander::LunarLander(const LunarLanderConfig& config)
    : SeededEnv(LunarLanderSpec(config.continuous)), config_(config) {
  config_.Validate();
  // The reference warns about, but accepts, values outside the recommended ranges.
  if (config_.wind_power < 0.0 || config_.wind_power > 20.0) {
    std::fprintf(stderr, "WARN: LunarLander: wind_power %g is outside the recommended [0, 20]\n",
                 config_.wind_power);
  }
  if (config_.turbulence_power < 0.0 || config_.turbulence_power > 2.0) {
    std::fprintf(stderr,
                 "WARN: LunarLander: turbulence_power %g is outside the recommended [0, 2]\n",
                 config_.turbulence_power);
  }
}

LunarLander::~LunarLander() = default;
LunarLander::LunarLander(LunarLander&&) noexcept = default;
LunarLander& LunarLander::operator=(LunarLander&&) noexcept = default;

void LunarLander::NewEpisode() {
  // A new world every episode (v3), so that nothing carries over between episodes.
  physics_.reset();
  physics_ = std::make_unique<Physics>(config_.gravity);
  Physics& p = *physics_;
  has_prev_shaping_ = false;

  // Terrain: 12 random heights, flattened around the pad, smoothed over 3 neighbours with the
  // reference's factor 0.33 (not 1/3, so the pad sits at 0.99 * helipad_y). Point 0 wraps around
  // to the last height, as Python's height[-1] does.
  std::array<double, kChunks + 1> height{};
  for (double& h : height) h = UniformDouble(rng(), 0.0, kH / 2);
  for (int i = 0; i < kChunks; ++i) chunk_x_[i] = kW / (kChunks - 1) * i;
  for (int i = kChunks / 2 - 2; i <= kChunks / 2 + 2; ++i) height[i] = kHelipadY;
  for (int i = 0; i < kChunks; ++i) {
    const double before = i == 0 ? height[kChunks] : height[i - 1];
    smooth_y_[i] = 0.33 * (before + height[i] + height[i + 1]);
  }

  // The moon: a static body with the base edge (default fixture: friction 0.2), then the 10
  // terrain edges (friction 0.1).
  b2BodyDef moon_def;
  p.moon = p.world.CreateBody(&moon_def);
  b2EdgeShape base;
  base.SetTwoSided(ToVec2(0, 0), ToVec2(kW, 0));
  b2FixtureDef base_def;
  base_def.shape = &base;
  p.moon->CreateFixture(&base_def);
  for (int i = 0; i + 1 < kChunks; ++i) {
    b2EdgeShape edge;
    edge.SetTwoSided(ToVec2(chunk_x_[i], smooth_y_[i]), ToVec2(chunk_x_[i + 1], smooth_y_[i + 1]));
    b2FixtureDef edge_def;
    edge_def.shape = &edge;
    edge_def.density = 0.0f;
    edge_def.friction = 0.1f;
    p.moon->CreateFixture(&edge_def);
  }

  // The lander, at the top centre.
  b2BodyDef lander_def;
  lander_def.type = b2_dynamicBody;
  lander_def.position = ToVec2(kW / 2, kH);
  lander_def.angle = 0.0f;
  p.lander = p.world.CreateBody(&lander_def);
  std::array<b2Vec2, kLanderPoly.size()> hull;
  for (std::size_t k = 0; k < hull.size(); ++k) {
    hull[k] = ToVec2(kLanderPoly[k][0] / kScale, kLanderPoly[k][1] / kScale);
  }
  b2PolygonShape lander_shape;
  lander_shape.Set(hull.data(), static_cast<int32>(hull.size()));
  b2FixtureDef lander_fixture;
  lander_fixture.shape = &lander_shape;
  lander_fixture.density = 5.0f;
  lander_fixture.friction = 0.1f;
  lander_fixture.restitution = 0.0f;
  lander_fixture.filter.categoryBits = kLanderCategory;
  lander_fixture.filter.maskBits = kMoonCategory;
  p.lander->CreateFixture(&lander_fixture);

  // The initial random push: a force, so it acts during the first world step only.
  const double force_x = UniformDouble(rng(), -kInitialRandom, kInitialRandom);
  const double force_y = UniformDouble(rng(), -kInitialRandom, kInitialRandom);
  p.lander->ApplyForceToCenter(ToVec2(force_x, force_y), true);

  // Wind phases (v3 draws them from the env's RNG at every reset).
  wind_idx_ = 0;
  torque_idx_ = 0;
  if (config_.enable_wind) {
    wind_idx_ = UniformInt(rng(), -9999, 9999);
    torque_idx_ = UniformInt(rng(), -9999, 9999);
  }

  // Legs i = -1 (the +x side) then i = +1, each followed by its joint to the lander's origin. The
  // joints start violated (the anchors do not coincide and the angle is outside the limits); the
  // first world step pulls the legs into place, as in the reference.
  for (int k = 0; k < 2; ++k) {
    const double i = k == 0 ? -1.0 : 1.0;
    b2BodyDef leg_def;
    leg_def.type = b2_dynamicBody;
    leg_def.position = ToVec2(kW / 2 - i * kLegAway / kScale, kH);
    leg_def.angle = static_cast<float>(i * 0.05);
    b2Body* leg = p.world.CreateBody(&leg_def);
    b2PolygonShape leg_shape;
    leg_shape.SetAsBox(static_cast<float>(kLegW / kScale), static_cast<float>(kLegH / kScale));
    b2FixtureDef leg_fixture;
    leg_fixture.shape = &leg_shape;
    leg_fixture.density = 1.0f;
    leg_fixture.restitution = 0.0f;
    leg_fixture.filter.categoryBits = kLegCategory;
    leg_fixture.filter.maskBits = kMoonCategory;
    leg->CreateFixture(&leg_fixture);
    p.legs[k] = leg;

    b2RevoluteJointDef joint;
    joint.bodyA = p.lander;
    joint.bodyB = leg;
    joint.localAnchorA = ToVec2(0, 0);
    joint.localAnchorB = ToVec2(i * kLegAway / kScale, kLegDown / kScale);
    joint.referenceAngle = leg->GetAngle() - p.lander->GetAngle();
    joint.enableMotor = true;
    joint.enableLimit = true;
    joint.maxMotorTorque = static_cast<float>(kLegSpringTorque);
    joint.motorSpeed = static_cast<float>(0.3 * i);
    if (k == 0) {
      joint.lowerAngle = static_cast<float>(0.9 - 0.5);
      joint.upperAngle = 0.9f;
    } else {
      joint.lowerAngle = -0.9f;
      joint.upperAngle = static_cast<float>(-0.9 + 0.5);
    }
    p.joints[k] = static_cast<b2RevoluteJoint*>(p.world.CreateJoint(&joint));
  }

  // The reference's reset returns the observation of a real step with no engine firing.
  StepPhysics(0.0, 0.0, 0.0);
}

StepResult LunarLander::OnStep(std::span<const float> action) {
  if (!config_.continuous) {
    // Action 2 is the main engine; 1 and 3 are the side engines with direction -1 and +1.
    const int a = ActionIndex(action);
    const bool side = a == 1 || a == 3;
    return StepPhysics(a == 2 ? 1.0 : 0.0, side ? 1.0 : 0.0, side ? a - 2.0 : 0.0);
  }

  // Clip to [-1, 1] and widen to double (v3). The main engine fires above 0 with throttle in
  // [0.5, 1]; a side engine fires when |lateral| > 0.5, with throttle in (0.5, 1].
  const double main = std::clamp(static_cast<double>(action[0]), -1.0, 1.0);
  const double lateral = std::clamp(static_cast<double>(action[1]), -1.0, 1.0);
  double m_power = 0.0;
  if (main > 0.0) m_power = (std::clamp(main, 0.0, 1.0) + 1.0) * 0.5;
  double s_power = 0.0;
  double direction = 0.0;
  if (std::abs(lateral) > 0.5) {
    direction = lateral > 0.0 ? 1.0 : -1.0;
    s_power = std::clamp(std::abs(lateral), 0.5, 1.0);
  }
  return StepPhysics(m_power, s_power, direction);
}

StepResult LunarLander::StepPhysics(double m_power, double s_power, double direction) {
  Physics& p = *physics_;

  // Wind and turbulence act only while neither leg touches the ground.
  if (config_.enable_wind && !(p.ground_contact[0] || p.ground_contact[1])) {
    const double wind = WindMagnitude(wind_idx_, config_.wind_power);
    ++wind_idx_;
    p.lander->ApplyForceToCenter(ToVec2(wind, 0.0), true);
    const double torque = WindMagnitude(torque_idx_, config_.turbulence_power);
    ++torque_idx_;
    p.lander->ApplyTorque(static_cast<float>(torque), true);
  }

  // The lander's frame and the engines' random dispersion (drawn every step, firing or not).
  const double angle = p.lander->GetAngle();
  const std::array<double, 2> tip = {std::sin(angle), std::cos(angle)};
  const std::array<double, 2> side = {-tip[1], tip[0]};
  const std::array<double, 2> dispersion = {UniformDouble(rng(), -1.0, 1.0) / kScale,
                                            UniformDouble(rng(), -1.0, 1.0) / kScale};

  // Main engine: an impulse along -tip through a point below the body origin.
  if (m_power > 0.0) {
    const double ox =
        tip[0] * (kMainEngineYLocation / kScale + 2 * dispersion[0]) + side[0] * dispersion[1];
    const double oy =
        -tip[1] * (kMainEngineYLocation / kScale + 2 * dispersion[0]) - side[1] * dispersion[1];
    const b2Vec2 position = p.lander->GetPosition();
    const double impulse_x = position.x + ox;
    const double impulse_y = position.y + oy;
    p.lander->ApplyLinearImpulse(
        ToVec2(-ox * kMainEnginePower * m_power, -oy * kMainEnginePower * m_power),
        ToVec2(impulse_x, impulse_y), true);
  }

  // Side engine: an impulse along -side * direction through a point beside the upper body. The
  // x offset uses 17 px rather than SIDE_ENGINE_HEIGHT (14), as the reference does.
  if (s_power > 0.0) {
    const double ox = tip[0] * dispersion[0] +
                      side[0] * (3 * dispersion[1] + direction * kSideEngineAway / kScale);
    const double oy = -tip[1] * dispersion[0] -
                      side[1] * (3 * dispersion[1] + direction * kSideEngineAway / kScale);
    const b2Vec2 position = p.lander->GetPosition();
    const double impulse_x = position.x + ox - tip[0] * 17 / kScale;
    const double impulse_y = position.y + oy + tip[1] * kSideEngineHeight / kScale;
    p.lander->ApplyLinearImpulse(
        ToVec2(-ox * kSideEnginePower * s_power, -oy * kSideEnginePower * s_power),
        ToVec2(impulse_x, impulse_y), true);
  }

  p.world.Step(static_cast<float>(1.0 / kFps), kVelocityIterations, kPositionIterations);
  UpdateState();

  // Shaped reward (0 on the first step of an episode), then fuel.
  const double shaping = Shaping(state_);
  double reward = has_prev_shaping_ ? shaping - prev_shaping_ : 0.0;
  prev_shaping_ = shaping;
  has_prev_shaping_ = true;
  reward -= m_power * kMainEngineCost;
  reward -= s_power * kSideEngineCost;
  return ApplyTerminationRules(reward, p.game_over, state_[0], p.lander->IsAwake());
}

void LunarLander::UpdateState() {
  const Physics& p = *physics_;
  state_ = NormalisedState(lander_kinematics(), p.ground_contact[0], p.ground_contact[1]);
  for (std::size_t k = 0; k < state_.size(); ++k) observation_[k] = static_cast<float>(state_[k]);
}

void LunarLander::RequireReset(const char* what) const {
  if (physics_ == nullptr) {
    throw std::logic_error(std::string("LunarLander: call Reset() before ") + what);
  }
}

LanderKinematics LunarLander::lander_kinematics() const {
  RL_CHECK(physics_ != nullptr) << "LunarLander: no episode yet (call Reset)";
  const b2Body& lander = *physics_->lander;
  return LanderKinematics{.x = lander.GetPosition().x,
                          .y = lander.GetPosition().y,
                          .vx = lander.GetLinearVelocity().x,
                          .vy = lander.GetLinearVelocity().y,
                          .angle = lander.GetAngle(),
                          .angular_velocity = lander.GetAngularVelocity()};
}

bool LunarLander::leg_ground_contact(int leg) const {
  RL_CHECK(physics_ != nullptr) << "LunarLander: no episode yet (call Reset)";
  RL_CHECK(leg == 0 || leg == 1) << "leg must be 0 or 1, got " << leg;
  return physics_->ground_contact[leg];
}

double LunarLander::leg_joint_angle(int leg) const {
  RL_CHECK(physics_ != nullptr) << "LunarLander: no episode yet (call Reset)";
  RL_CHECK(leg == 0 || leg == 1) << "leg must be 0 or 1, got " << leg;
  return physics_->joints[leg]->GetJointAngle();
}

bool LunarLander::game_over() const {
  RL_CHECK(physics_ != nullptr) << "LunarLander: no episode yet (call Reset)";
  return physics_->game_over;
}

bool LunarLander::lander_awake() const {
  RL_CHECK(physics_ != nullptr) << "LunarLander: no episode yet (call Reset)";
  return physics_->lander->IsAwake();
}

std::vector<std::vector<std::array<double, 2>>> LunarLander::body_polygons() const {
  RL_CHECK(physics_ != nullptr) << "LunarLander: no episode yet (call Reset)";
  std::vector<std::vector<std::array<double, 2>>> polygons;
  for (const b2Body* body : {physics_->lander, physics_->legs[0], physics_->legs[1]}) {
    for (const b2Fixture* f = body->GetFixtureList(); f != nullptr; f = f->GetNext()) {
      RL_CHECK(f->GetType() == b2Shape::e_polygon) << "the lander's bodies are polygons";
      const auto& shape = static_cast<const b2PolygonShape&>(*f->GetShape());
      std::vector<std::array<double, 2>>& outline = polygons.emplace_back();
      for (int32 k = 0; k < shape.m_count; ++k) {
        const b2Vec2 v = b2Mul(body->GetTransform(), shape.m_vertices[k]);
        outline.push_back({v.x, v.y});
      }
    }
  }
  return polygons;
}

void LunarLander::SetLanderKinematics(const LanderKinematics& kinematics) {
  RequireReset("SetLanderKinematics()");
  Physics& p = *physics_;

  // Move the lander, remembering where it was so the legs can follow.
  const b2Transform old_lander = p.lander->GetTransform();
  const float old_angle = p.lander->GetAngle();
  const float new_angle = static_cast<float>(kinematics.angle);
  p.lander->SetTransform(ToVec2(kinematics.x, kinematics.y), new_angle);
  const b2Vec2 velocity = ToVec2(kinematics.vx, kinematics.vy);
  const float omega = static_cast<float>(kinematics.angular_velocity);
  p.lander->SetLinearVelocity(velocity);
  p.lander->SetAngularVelocity(omega);
  p.lander->SetAwake(true);

  // Each leg keeps its pose relative to the lander and moves with it as one rigid body.
  const b2Transform new_lander = p.lander->GetTransform();
  const b2Vec2 centre = p.lander->GetWorldCenter();
  for (b2Body* leg : p.legs) {
    const b2Transform relative = b2MulT(old_lander, leg->GetTransform());
    const b2Transform moved = b2Mul(new_lander, relative);
    leg->SetTransform(moved.p, leg->GetAngle() - old_angle + new_angle);
    leg->SetLinearVelocity(velocity + b2Cross(omega, leg->GetWorldCenter() - centre));
    leg->SetAngularVelocity(omega);
    leg->SetAwake(true);
  }

  UpdateState();
  prev_shaping_ = Shaping(state_);
  has_prev_shaping_ = true;
}

std::array<double, 8> LunarLander::NormalisedState(const LanderKinematics& k, bool leg0_contact,
                                                   bool leg1_contact) {
  constexpr double kHalfW = kViewportW / kScale / 2;
  constexpr double kHalfH = kViewportH / kScale / 2;
  return {(k.x - kHalfW) / kHalfW,
          (k.y - (kHelipadY + kLegDown / kScale)) / kHalfH,
          k.vx * kHalfW / kFps,
          k.vy * kHalfH / kFps,
          k.angle,
          20.0 * k.angular_velocity / kFps,
          leg0_contact ? 1.0 : 0.0,
          leg1_contact ? 1.0 : 0.0};
}

double LunarLander::Shaping(const std::array<double, 8>& s) {
  return -100 * std::sqrt(s[0] * s[0] + s[1] * s[1]) - 100 * std::sqrt(s[2] * s[2] + s[3] * s[3]) -
         100 * std::abs(s[4]) + 10 * s[6] + 10 * s[7];
}

StepResult LunarLander::ApplyTerminationRules(double reward, bool game_over, double s0,
                                              bool lander_awake) {
  StepResult result{.reward = reward, .terminated = false, .truncated = false};
  if (game_over || std::abs(s0) >= 1.0) {
    result.terminated = true;
    result.reward = -100;
  }
  if (!lander_awake) {
    result.terminated = true;
    result.reward = +100;
  }
  return result;
}

double LunarLander::WindMagnitude(int64_t index, double power) {
  const double i = static_cast<double>(index);
  return std::tanh(std::sin(0.02 * i) + std::sin(std::numbers::pi * 0.01 * i)) * power;
}

// Registered as LunarLander-v3 and LunarLanderContinuous-v3 (env_list.inc).
std::unique_ptr<Env> MakeLunarLanderV3(const EnvIdParts&) {
  return std::make_unique<LunarLander>();
}

std::unique_ptr<Env> MakeLunarLanderContinuousV3(const EnvIdParts&) {
  return std::make_unique<LunarLander>(LunarLanderConfig{.continuous = true});
}

}  // namespace rl::envs
