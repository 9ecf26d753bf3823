// CarRacing physics on Box2D 2.4.1.
//
// The reference runs pybox2d (a Box2D 2.3 core). Where this port differs:
// - Each Reset builds a new Box2D world; the reference reuses one world across episodes. A fresh
//   world makes an episode depend on its seed alone, not on the episodes before it (proxy ids and
//   contact order otherwise carry over).
// - Box2D 2.4 rewrote the revolute joint (limits are speculative, motor and limit are solved
//   apart; environments.md 2.10). The steering joints therefore reach their +-0.4 rad stops
//   slightly differently; the tyre model, which gives the car all its grip, is unchanged.
// - The reference draws with numpy's PCG64; here the env's mt19937_64 (envs/rng.h) draws, with
//   numpy's rule for uniform doubles. Tracks are generated exactly as specified, from other
//   random numbers, so a seed gives another track than the reference's for the same seed.
// - Skid marks are not simulated: they are drawn only in the reference's human and rgb_array
//   videos, never in observations, and change nothing else.
// - Domain randomisation draws its colours at every Reset; the reference also draws them once in
//   its constructor, from an unseeded generator, and that draw is overwritten by the first reset.
// - Bodies and tiles are told apart by pointer and by fixture user data (the tile's index + 1).
#include "envs/box2d/car_racing.h"

#include <box2d/box2d.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>

#include "common/check.h"
#include "envs/env_list.h"
#include "envs/render_args.h"
#include "envs/specs.h"

namespace rl::envs {
namespace {

// Car constants (environments.md 3.2), in the reference's units before the SIZE factor.
constexpr double kSize = 0.02;
constexpr double kEnginePower = 100000000 * kSize * kSize;      // 40,000
constexpr double kWheelMomentOfInertia = 4000 * kSize * kSize;  // 1.6
constexpr double kFrictionLimit = 1000000 * kSize * kSize;      // 400 on the road
constexpr double kGrassFriction = 0.6;                          // 240 on grass
constexpr double kWheelR = 27;
constexpr double kWheelW = 14;
constexpr double kWheelRad = kWheelR * kSize;                  // 0.54
constexpr double kFrictionStiffness = 205000 * kSize * kSize;  // 82
constexpr double kBrakeForce = 15;                             // rad/s per step at brake 1
constexpr double kMaxMotorTorque = 180 * 900 * kSize * kSize;  // 64.8
constexpr double kSteerLimit = 0.4;
constexpr double kDt = 1.0 / CarRacing::kFps;
constexpr std::array<std::array<double, 2>, 4> kWheelPos = {
    {{-55, +80}, {+55, +80}, {-55, -82}, {+55, -82}}};
constexpr std::array<std::array<double, 2>, 4> kHullPoly1 = {
    {{-60, +130}, {+60, +130}, {+60, +110}, {-60, +110}}};
constexpr std::array<std::array<double, 2>, 4> kHullPoly2 = {
    {{-15, +120}, {+15, +120}, {+20, +20}, {-20, +20}}};
constexpr std::array<std::array<double, 2>, 8> kHullPoly3 = {{{+25, +20},
                                                              {+50, -10},
                                                              {+50, -40},
                                                              {+20, -90},
                                                              {-20, -90},
                                                              {-50, -40},
                                                              {-50, -10},
                                                              {-25, +20}}};
constexpr std::array<std::array<double, 2>, 4> kHullPoly4 = {
    {{-50, -120}, {+50, -120}, {+50, -90}, {-50, -90}}};
constexpr std::array<std::array<double, 2>, 4> kWheelPoly = {
    {{-kWheelW, +kWheelR}, {+kWheelW, +kWheelR}, {+kWheelW, -kWheelR}, {-kWheelW, -kWheelR}}};

constexpr Rgb kHullColor{204, 0, 0};
constexpr Rgb kWheelColor{0, 0, 0};
constexpr Rgb kWheelWhite{77, 77, 77};
constexpr Rgb kKerbWhite{255, 255, 255};
constexpr Rgb kKerbRed{255, 0, 0};

// numpy's sign.
double Sign(double v) { return v > 0 ? 1.0 : (v < 0 ? -1.0 : 0.0); }

// Drawing truncates the reference's float colours with int().
Rgb Truncate(const std::array<double, 3>& c) {
  return Rgb{static_cast<uint8_t>(c[0]), static_cast<uint8_t>(c[1]), static_cast<uint8_t>(c[2])};
}

b2Vec2 ToVec2(double x, double y) { return b2Vec2(static_cast<float>(x), static_cast<float>(y)); }

template <std::size_t N>
b2PolygonShape Polygon(const std::array<std::array<double, 2>, N>& points, double scale) {
  std::array<b2Vec2, N> v;
  for (std::size_t k = 0; k < N; ++k) v[k] = ToVec2(points[k][0] * scale, points[k][1] * scale);
  b2PolygonShape shape;
  shape.Set(v.data(), static_cast<int32>(N));
  return shape;
}

}  // namespace

// The Box2D world of one episode: the tiles, the car, the tyre state and the tile contact
// listener (environments.md 3.7), whose callbacks run inside b2World::Step.
struct CarRacing::Physics final : public b2ContactListener {
  explicit Physics(double lap_percent) : world(b2Vec2(0, 0)), lap_complete_percent(lap_percent) {
    world.SetContactListener(this);
  }
  ~Physics() override { world.SetContactListener(nullptr); }
  Physics(const Physics&) = delete;
  Physics& operator=(const Physics&) = delete;

  struct Wheel {
    b2Body* body = nullptr;
    b2RevoluteJoint* joint = nullptr;
    double gas = 0;
    double brake = 0;
    double steer = 0;
    double omega = 0;
    double phase = 0;
    std::vector<int> tiles;  // A set: the tiles under the wheel.
  };

  void BeginContact(b2Contact* contact) override { Touch(contact, true); }
  void EndContact(b2Contact* contact) override { Touch(contact, false); }

  // Any contact with a tile, begin or end, wheel or hull, gives the tile back the plain road
  // colour; only wheels visit tiles.
  void Touch(b2Contact* contact, bool begin) {
    b2Fixture* a = contact->GetFixtureA();
    b2Fixture* b = contact->GetFixtureB();
    int tile = -1;
    b2Body* other = nullptr;
    if (a->GetUserData().pointer != 0) {
      tile = static_cast<int>(a->GetUserData().pointer) - 1;
      other = b->GetBody();
    }
    if (b->GetUserData().pointer != 0) {
      tile = static_cast<int>(b->GetUserData().pointer) - 1;
      other = a->GetBody();
    }
    if (tile < 0) return;
    recolored[tile] = 1;
    Wheel* wheel = nullptr;
    for (Wheel& w : wheels) {
      if (w.body == other) wheel = &w;
    }
    if (wheel == nullptr) return;
    auto it = std::find(wheel->tiles.begin(), wheel->tiles.end(), tile);
    if (!begin) {
      if (it != wheel->tiles.end()) wheel->tiles.erase(it);
      return;
    }
    if (it == wheel->tiles.end()) wheel->tiles.push_back(tile);
    if (!visited[tile]) {
      const double n = static_cast<double>(visited.size());
      visited[tile] = 1;
      reward += 1000.0 / n;
      visited_count += 1;
      if (tile == 0 && visited_count / n > lap_complete_percent) new_lap = true;
    }
  }

  b2World world;
  double lap_complete_percent;
  b2Body* hull = nullptr;
  std::array<Wheel, 4> wheels{};
  std::vector<uint8_t> visited;    // Per tile (the reference's road_visited).
  std::vector<uint8_t> recolored;  // Per tile: touched, so drawn in the plain road colour.
  double reward = 0;               // The reference's self.reward.
  int visited_count = 0;
  bool new_lap = false;
};

void CarRacingConfig::Validate() const {
  if (!(lap_complete_percent >= 0 && lap_complete_percent <= 1)) {
    throw std::invalid_argument("CarRacingConfig: lap_complete_percent must be in [0, 1], got " +
                                std::to_string(lap_complete_percent));
  }
  if (supersample < 1 || supersample > 8) {
    throw std::invalid_argument("CarRacingConfig: supersample must be in [1, 8], got " +
                                std::to_string(supersample));
  }
  if (off_track_after < 0) {
    throw std::invalid_argument("CarRacingConfig: off_track_after must be >= 0, got " +
                                std::to_string(off_track_after));
  }
  if (pedals && !continuous) {
    throw std::invalid_argument("CarRacingConfig: pedals needs continuous actions");
  }
  if (off_track_grace < 0) {
    throw std::invalid_argument("CarRacingConfig: off_track_grace must be >= 0, got " +
                                std::to_string(off_track_grace));
  }
}

double CarRacingCar::speed() const { return std::hypot(velocity.x, velocity.y); }

CarRacing::CarRacing(const CarRacingConfig& config)
    : SeededEnv(CarRacingSpec(config.continuous, config.pedals && config.continuous)),
      config_(config) {
  config_.Validate();
}

CarRacing::~CarRacing() = default;
CarRacing::CarRacing(CarRacing&&) noexcept = default;
CarRacing& CarRacing::operator=(CarRacing&&) noexcept = default;

void CarRacing::NewEpisode() {
  if (config_.domain_randomize) {
    for (double& c : road_color_) c = UniformDouble(rng(), 0, 210);
    for (double& c : background_color_) c = UniformDouble(rng(), 0, 210);
    grass_color_ = background_color_;
    grass_color_[UniformInt(rng(), 0, 3)] += 20;
  }
  GenerateCarRacingTrack(rng(), &track_);
  const int n = track_.size();

  physics_ = std::make_unique<Physics>(config_.lap_complete_percent);
  Physics& p = *physics_;
  p.visited.assign(n, 0);
  p.recolored.assign(n, 0);

  // Tiles: static sensor bodies, one quad each, found in contacts by their fixture's user data.
  for (int i = 0; i < n; ++i) {
    std::array<b2Vec2, 4> v;
    for (int k = 0; k < 4; ++k) v[k] = ToVec2(track_.tiles[i][k].x, track_.tiles[i][k].y);
    b2PolygonShape shape;
    shape.Set(v.data(), 4);
    b2BodyDef body_def;  // Static, at the origin.
    b2Body* body = p.world.CreateBody(&body_def);
    b2FixtureDef fixture;
    fixture.shape = &shape;
    fixture.friction = 0.2f;
    fixture.density = 0;
    fixture.isSensor = true;
    fixture.userData.pointer = static_cast<uintptr_t>(i) + 1;
    body->CreateFixture(&fixture);
  }

  // The car at node 0, facing along the road (environments.md 3.6 step 7).
  const CarRacingTrack::Node& start = track_.nodes[0];
  b2BodyDef hull_def;
  hull_def.type = b2_dynamicBody;
  hull_def.position = ToVec2(start.x, start.y);
  hull_def.angle = static_cast<float>(start.beta);
  p.hull = p.world.CreateBody(&hull_def);
  const std::array<b2PolygonShape, 4> hull_shapes = {
      Polygon(kHullPoly1, kSize), Polygon(kHullPoly2, kSize), Polygon(kHullPoly3, kSize),
      Polygon(kHullPoly4, kSize)};
  for (const b2PolygonShape& shape : hull_shapes) p.hull->CreateFixture(&shape, 1.0f);
  const b2PolygonShape wheel_shape = Polygon(kWheelPoly, kSize);
  for (int k = 0; k < 4; ++k) {
    Physics::Wheel& w = p.wheels[k];
    b2BodyDef wheel_def;
    wheel_def.type = b2_dynamicBody;
    // Not rotated by the start angle, as in the reference: the joints pull the wheels into place
    // during the reset step.
    wheel_def.position =
        ToVec2(start.x + kWheelPos[k][0] * kSize, start.y + kWheelPos[k][1] * kSize);
    wheel_def.angle = static_cast<float>(start.beta);
    w.body = p.world.CreateBody(&wheel_def);
    b2FixtureDef fixture;
    fixture.shape = &wheel_shape;
    fixture.density = 0.1f;
    fixture.filter.categoryBits = 0x0020;
    fixture.filter.maskBits = 0x001;
    fixture.restitution = 0;
    w.body->CreateFixture(&fixture);
    b2RevoluteJointDef joint;
    joint.bodyA = p.hull;
    joint.bodyB = w.body;
    joint.localAnchorA = ToVec2(kWheelPos[k][0] * kSize, kWheelPos[k][1] * kSize);
    joint.localAnchorB = b2Vec2(0, 0);
    joint.referenceAngle = 0;  // Both bodies start at the same angle.
    joint.enableMotor = true;
    joint.enableLimit = true;
    joint.maxMotorTorque = static_cast<float>(kMaxMotorTorque);
    joint.motorSpeed = 0;
    joint.lowerAngle = static_cast<float>(-kSteerLimit);
    joint.upperAngle = static_cast<float>(kSteerLimit);
    w.joint = static_cast<b2RevoluteJoint*>(p.world.CreateJoint(&joint));
  }

  // The picture's fixed parts: colours and the road polygons, each tile followed by its kerb.
  scene_ = CarRacingScene{};
  scene_.background = Truncate(background_color_);
  scene_.grass = Truncate(grass_color_);
  scene_.road.clear();
  scene_.road.reserve(static_cast<std::size_t>(n) + track_.kerbs.size());
  road_index_.assign(n, 0);
  std::size_t kerb = 0;
  for (int i = 0; i < n; ++i) {
    road_index_[i] = static_cast<int>(scene_.road.size());
    CarRacingScene::Polygon tile;
    for (int k = 0; k < 4; ++k) tile.vertices[k] = track_.tiles[i][k];
    tile.count = 4;
    std::array<double, 3> color = road_color_;
    for (double& c : color) c += 0.01 * (i % 3) * 255;
    tile.color = Truncate(color);
    scene_.road.push_back(tile);
    if (kerb < track_.kerbs.size() && track_.kerbs[kerb].tile == i) {
      CarRacingScene::Polygon strip;
      for (int k = 0; k < 4; ++k) strip.vertices[k] = track_.kerbs[kerb].quad[k];
      strip.count = 4;
      strip.color = track_.kerbs[kerb].red ? kKerbRed : kKerbWhite;
      scene_.road.push_back(strip);
      ++kerb;
    }
  }

  prev_reward_ = 0;
  t_ = 0;
  lap_finished_ = false;
  off_track_frames_ = 0;
  // The reference's reset ends with step(None): physics without an action or reward rules.
  Advance();
}

void CarRacing::RequireReset(const char* what) const {
  if (physics_ == nullptr) {
    throw std::logic_error(std::string("CarRacing: ") + what + " before the first Reset");
  }
}

void CarRacing::Control(double steer, double gas, double brake) {
  Physics& p = *physics_;
  for (int k = 0; k < 2; ++k) p.wheels[k].steer = steer;
  gas = std::clamp(gas, 0.0, 1.0);
  for (int k = 2; k < 4; ++k) {  // Rear-wheel drive; the gas rises by 0.1 per step at most.
    const double diff = std::min(gas - p.wheels[k].gas, 0.1);
    p.wheels[k].gas += diff;
  }
  for (Physics::Wheel& w : p.wheels) w.brake = brake;
}

void CarRacing::Advance() {
  Physics& p = *physics_;
  // The tyre model (environments.md 3.8), wheel by wheel, before the world step.
  for (Physics::Wheel& w : p.wheels) {
    const double joint_angle = w.joint->GetJointAngle();
    const double steer_error = w.steer - joint_angle;
    w.joint->SetMotorSpeed(
        static_cast<float>(Sign(steer_error) * std::min(50.0 * std::abs(steer_error), 3.0)));
    const double friction_limit =
        w.tiles.empty() ? kFrictionLimit * kGrassFriction : kFrictionLimit;  // road_friction 1
    const b2Vec2 forw = w.body->GetWorldVector(b2Vec2(0, 1));
    const b2Vec2 side = w.body->GetWorldVector(b2Vec2(1, 0));
    const b2Vec2 v = w.body->GetLinearVelocity();
    const double vf = double{forw.x} * v.x + double{forw.y} * v.y;
    const double vs = double{side.x} * v.x + double{side.y} * v.y;
    w.omega += kDt * kEnginePower * w.gas / kWheelMomentOfInertia / (std::abs(w.omega) + 5.0);
    if (w.brake >= 0.9) {
      w.omega = 0;
    } else if (w.brake > 0) {
      const double val = std::min(kBrakeForce * w.brake, std::abs(w.omega));
      w.omega += -Sign(w.omega) * val;
    }
    w.phase += w.omega * kDt;
    const double vr = w.omega * kWheelRad;
    double f_force = (-vf + vr) * kFrictionStiffness;
    double p_force = -vs * kFrictionStiffness;
    const double force = std::sqrt(f_force * f_force + p_force * p_force);
    if (force > friction_limit) {  // Slipping: the force is capped at the friction limit.
      f_force = f_force / force * friction_limit;
      p_force = p_force / force * friction_limit;
    }
    w.omega -= kDt * f_force * kWheelRad / kWheelMomentOfInertia;
    w.body->ApplyForceToCenter(
        ToVec2(p_force * side.x + f_force * forw.x, p_force * side.y + f_force * forw.y), true);
  }
  p.world.Step(static_cast<float>(kDt), kVelocityIterations, kPositionIterations);
  t_ += kDt;
  scene_stale_ = true;
  pixels_stale_ = true;
  observation_stale_ = true;
}

StepResult CarRacing::Finish() {
  Physics& p = *physics_;
  p.reward -= 0.1;
  StepResult result;
  result.reward = p.reward - prev_reward_;
  prev_reward_ = p.reward;
  lap_finished_ = false;
  if (config_.lap_ends && (p.visited_count == track_.size() || p.new_lap)) {
    result.terminated = true;
    lap_finished_ = true;
  }
  const b2Vec2 position = p.hull->GetPosition();
  if (std::abs(position.x) > CarRacingTrack::kPlayfield ||
      std::abs(position.y) > CarRacingTrack::kPlayfield) {
    result.terminated = true;
    lap_finished_ = false;
    result.reward = -100;
  }
  return result;
}

StepResult CarRacing::OnStep(std::span<const float> action) {
  if (config_.continuous) {
    const double steer = std::clamp(double{action[0]}, -1.0, 1.0);
    if (config_.pedals) {
      const double pedal = std::clamp(double{action[1]}, -1.0, 1.0);
      Control(-steer, std::max(pedal, 0.0), std::max(-pedal, 0.0));
    } else {
      const double brake = std::clamp(double{action[2]}, 0.0, 1.0);
      Control(-steer, action[1], brake);
    }
  } else {
    const int a = ActionIndex(action);
    Control(-0.6 * (a == 1) + 0.6 * (a == 2), 0.2 * (a == 3), 0.8 * (a == 4));
  }
  Advance();
  StepResult result = Finish();
  if (config_.off_track && elapsed_steps() > config_.off_track_after) {
    off_track_frames_ = OffTrack() ? off_track_frames_ + 1 : 0;
    if (off_track_frames_ > config_.off_track_grace) {
      result.reward = -10.0;
      result.terminated = true;
    }
  }
  return result;
}

bool CarRacing::OffTrack() const {
  // Row 75 and columns 41, 42, 52, 53 of the 96 x 96 picture: green above 200 on both sides.
  const std::vector<uint8_t>& picture = Picture();
  constexpr std::size_t kRow = 75;
  for (std::size_t column : {41, 42, 52, 53}) {
    if (picture[(kRow * kStateSize + column) * 3 + 1] <= 200) return false;
  }
  return true;
}

const CarRacingTrack& CarRacing::track() const {
  RequireReset("track");
  return track_;
}

double CarRacing::episode_reward() const {
  RequireReset("episode_reward");
  return physics_->reward;
}

int CarRacing::tiles_visited() const {
  RequireReset("tiles_visited");
  return physics_->visited_count;
}

bool CarRacing::tile_visited(int i) const {
  RequireReset("tile_visited");
  RL_CHECK(i >= 0 && i < track_.size()) << "tile " << i << " of " << track_.size();
  return physics_->visited[i] != 0;
}

CarRacingCar CarRacing::car() const {
  RequireReset("car");
  const Physics& p = *physics_;
  CarRacingCar car;
  car.position = {p.hull->GetPosition().x, p.hull->GetPosition().y};
  car.angle = p.hull->GetAngle();
  car.velocity = {p.hull->GetLinearVelocity().x, p.hull->GetLinearVelocity().y};
  car.angular_velocity = p.hull->GetAngularVelocity();
  for (int k = 0; k < 4; ++k) {
    const Physics::Wheel& w = p.wheels[k];
    car.wheels[k] = CarRacingWheel{.gas = w.gas,
                                   .brake = w.brake,
                                   .steer = w.steer,
                                   .omega = w.omega,
                                   .phase = w.phase,
                                   .tiles = static_cast<int>(w.tiles.size()),
                                   .joint_angle = w.joint->GetJointAngle(),
                                   .position = {w.body->GetPosition().x, w.body->GetPosition().y}};
  }
  return car;
}

const CarRacingScene& CarRacing::scene() const {
  RequireReset("scene");
  UpdateScene();
  return scene_;
}

void CarRacing::UpdateScene() const {
  if (!scene_stale_) return;
  const Physics& p = *physics_;
  const std::size_t n = p.recolored.size();
  const Rgb road = Truncate(road_color_);
  for (std::size_t i = 0; i < n; ++i) {
    if (p.recolored[i]) scene_.road[road_index_[i]].color = road;
  }
  // The car: each wheel's box then, when visible, its tread; then the hull's polygons.
  const auto to_world = [](const b2Body* body, double x, double y) {
    const b2Vec2 w = body->GetWorldPoint(ToVec2(x, y));
    return Vec2d{w.x, w.y};
  };
  scene_.car.clear();
  for (const Physics::Wheel& w : p.wheels) {
    CarRacingScene::Polygon box{.count = 4, .color = kWheelColor};
    for (int k = 0; k < 4; ++k) {
      box.vertices[k] = to_world(w.body, kWheelPoly[k][0] * kSize, kWheelPoly[k][1] * kSize);
    }
    scene_.car.push_back(box);
    // The tread: a grey band that turns with the phase, hidden on the wheel's far half.
    const double a1 = w.phase;
    const double a2 = w.phase + 1.2;
    const double s1 = std::sin(a1);
    const double s2 = std::sin(a2);
    double c1 = std::cos(a1);
    double c2 = std::cos(a2);
    if (s1 > 0 && s2 > 0) continue;
    if (s1 > 0) c1 = Sign(c1);
    if (s2 > 0) c2 = Sign(c2);
    const double hw = kWheelW * kSize;
    CarRacingScene::Polygon tread{.count = 4, .color = kWheelWhite};
    tread.vertices[0] = to_world(w.body, -hw, kWheelRad * c1);
    tread.vertices[1] = to_world(w.body, +hw, kWheelRad * c1);
    tread.vertices[2] = to_world(w.body, +hw, kWheelRad * c2);
    tread.vertices[3] = to_world(w.body, -hw, kWheelRad * c2);
    scene_.car.push_back(tread);
  }
  const auto add_hull = [&](const auto& poly) {
    CarRacingScene::Polygon shape{.count = static_cast<int>(poly.size()), .color = kHullColor};
    for (std::size_t k = 0; k < poly.size(); ++k) {
      shape.vertices[k] = to_world(p.hull, poly[k][0] * kSize, poly[k][1] * kSize);
    }
    scene_.car.push_back(shape);
  };
  add_hull(kHullPoly1);
  add_hull(kHullPoly2);
  add_hull(kHullPoly3);
  add_hull(kHullPoly4);

  scene_.t = t_;
  scene_.hull_position = {p.hull->GetPosition().x, p.hull->GetPosition().y};
  scene_.hull_angle = p.hull->GetAngle();
  const b2Vec2 v = p.hull->GetLinearVelocity();
  scene_.true_speed = std::sqrt(double{v.x} * v.x + double{v.y} * v.y);
  for (int k = 0; k < 4; ++k) scene_.wheel_omega[k] = p.wheels[k].omega;
  scene_.front_joint_angle = p.wheels[0].joint->GetJointAngle();
  scene_.hull_angular_velocity = p.hull->GetAngularVelocity();
  scene_.score = p.reward;
  scene_stale_ = false;
}

int CarRacing::SupersampleFor(int width, int height) const {
  const int per_x = (CarRacingScene::kSurfaceWidth + width - 1) / width;
  const int per_y = (CarRacingScene::kSurfaceHeight + height - 1) / height;
  return std::clamp(std::max(per_x, per_y), 1, config_.supersample);
}

void CarRacing::RenderSized(int width, int height, std::vector<uint8_t>* rgb) const {
  RequireReset("RenderSized");
  CheckRenderArgs(*this, "CarRacing", width, height, rgb);
  UpdateScene();
  DrawCarRacing(scene_, width, height, SupersampleFor(width, height), rgb);
}

void CarRacing::Render(std::vector<uint8_t>* rgb, int* width, int* height) const {
  RL_CHECK(rgb != nullptr && width != nullptr && height != nullptr)
      << "Render needs an output buffer and width and height outputs";
  *rgb = Picture();
  *width = kStateSize;
  *height = kStateSize;
}

const std::vector<uint8_t>& CarRacing::Picture() const {
  RequireReset("Render");
  if (pixels_stale_) {
    RenderSized(kStateSize, kStateSize, &pixels_);
    pixels_stale_ = false;
  }
  return pixels_;
}

std::span<const float> CarRacing::observation() const {
  RequireReset("observation");
  if (observation_stale_) {
    const std::vector<uint8_t>& pixels = Picture();
    observation_.resize(pixels.size());
    for (std::size_t k = 0; k < pixels.size(); ++k) observation_[k] = pixels[k] / 255.0f;
    observation_stale_ = false;
  }
  return observation_;
}

namespace {

// CarRacing with the rules the id sets (pixel_spec.h): 1,000 frames; an episode also ends when
// every tile is visited (unless lap-ends is 0), the car leaves the playfield, or (off-track) the
// track after the no-op start.
std::unique_ptr<Env> MakeCarRacing(const EnvIdParts& id, bool continuous) {
  return std::make_unique<CarRacing>(CarRacingConfig{.continuous = continuous,
                                                     .lap_ends = id.lap_ends,
                                                     .off_track = id.off_track,
                                                     .off_track_after = id.image.noop_start,
                                                     .off_track_grace = id.off_track_grace,
                                                     .pedals = id.pedals});
}

}  // namespace

// Registered as CarRacing-v3 and CarRacingDiscrete-v3 (env_list.inc).
std::unique_ptr<Env> MakeCarRacingV3(const EnvIdParts& id) { return MakeCarRacing(id, true); }

std::unique_ptr<Env> MakeCarRacingDiscreteV3(const EnvIdParts& id) {
  return MakeCarRacing(id, false);
}

}  // namespace rl::envs
