// Track generation, following environments.md 3.5 step by step (the reference's _create_track).
// Indices that the reference takes with Python's negative wrap (track[i - 1] for i = 0, the kerb
// propagation's border[i - neg]) wrap the same way here, through Wrap().
#include "envs/box2d/car_racing_track.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

#include "envs/rng.h"

namespace rl::envs {
namespace {

constexpr double kPi = std::numbers::pi;
using Track = CarRacingTrack;

// Python's a[i] for -n <= i < n.
int Wrap(int i, int n) { return i < 0 ? i + n : i; }

// numpy's sign: -1, 0 or +1.
double Sign(double v) { return v > 0 ? 1.0 : (v < 0 ? -1.0 : 0.0); }

struct Checkpoint {
  double alpha;
  double x;
  double y;
};

}  // namespace

double CarRacingTrack::Length() const {
  double length = 0;
  for (int i = 0; i < size(); ++i) {
    const Node& a = nodes[Wrap(i - 1, size())];
    const Node& b = nodes[i];
    length += std::hypot(b.x - a.x, b.y - a.y);
  }
  return length;
}

bool TryGenerateCarRacingTrack(std::mt19937_64& rng, CarRacingTrack* track) {
  constexpr int kCheckpoints = Track::kCheckpoints;
  // 1. Checkpoints: both draws happen for every c, even where they are overridden.
  std::array<Checkpoint, kCheckpoints> checkpoints{};
  const double start_alpha = 2 * kPi * (-0.5) / kCheckpoints;
  for (int c = 0; c < kCheckpoints; ++c) {
    const double noise = UniformDouble(rng, 0, 2 * kPi * 1 / kCheckpoints);
    double alpha = 2 * kPi * c / kCheckpoints + noise;
    double rad = UniformDouble(rng, Track::kTrackRad / 3, Track::kTrackRad);
    if (c == 0) {
      alpha = 0;
      rad = 1.5 * Track::kTrackRad;
    }
    if (c == kCheckpoints - 1) {
      alpha = 2 * kPi * c / kCheckpoints;
      rad = 1.5 * Track::kTrackRad;
    }
    checkpoints[c] = {alpha, rad * std::cos(alpha), rad * std::sin(alpha)};
  }

  // 2. The walk from checkpoint to checkpoint.
  double x = 1.5 * Track::kTrackRad;
  double y = 0;
  double beta = 0;
  int dest_i = 0;
  int laps = 0;
  int no_freeze = 2500;
  bool visited_other_side = false;
  std::vector<Track::Node> walk;
  walk.reserve(no_freeze);
  while (true) {
    double alpha = std::atan2(y, x);
    if (visited_other_side && alpha > 0) {
      laps += 1;
      visited_other_side = false;
    }
    if (alpha < 0) {
      visited_other_side = true;
      alpha += 2 * kPi;
    }
    Checkpoint dest{};
    while (true) {  // Find the destination; wrap alpha back a turn when every checkpoint is behind.
      bool failed = true;
      while (true) {
        dest = checkpoints[dest_i % kCheckpoints];
        if (alpha <= dest.alpha) {
          failed = false;
          break;
        }
        dest_i += 1;
        if (dest_i % kCheckpoints == 0) break;
      }
      if (!failed) break;
      alpha -= 2 * kPi;
    }
    const double r1x = std::cos(beta);
    const double r1y = std::sin(beta);
    const double p1x = -r1y;
    const double p1y = r1x;
    double proj = r1x * (dest.x - x) + r1y * (dest.y - y);  // Destination along the radius.
    while (beta - alpha > 1.5 * kPi) beta -= 2 * kPi;
    while (beta - alpha < -1.5 * kPi) beta += 2 * kPi;
    const double prev_beta = beta;
    proj *= Track::kScale;
    if (proj > 0.3) beta -= std::min(Track::kTurnRate, std::abs(0.001 * proj));
    if (proj < -0.3) beta += std::min(Track::kTurnRate, std::abs(0.001 * proj));
    x += p1x * Track::kDetailStep;
    y += p1y * Track::kDetailStep;
    walk.push_back({alpha, prev_beta * 0.5 + beta * 0.5, x, y});
    if (laps > 4) break;
    no_freeze -= 1;
    if (no_freeze == 0) break;
  }

  // 3. Cut one lap: the last two passes through the start angle, scanning backwards.
  int i1 = -1;
  int i2 = -1;
  for (int i = static_cast<int>(walk.size()) - 1;; --i) {
    if (i <= 0) return false;
    const bool pass_through_start = walk[i].alpha > start_alpha && walk[i - 1].alpha <= start_alpha;
    if (pass_through_start && i2 == -1) {
      i2 = i;
    } else if (pass_through_start && i1 == -1) {
      i1 = i;
      break;
    }
  }
  if (i2 - 1 <= i1) return false;  // An empty slice; the reference would fail on track[0].
  std::vector<Track::Node>& nodes = track->nodes;
  nodes.assign(walk.begin() + i1, walk.begin() + (i2 - 1));  // Python's track[i1 : i2 - 1].
  const int n = static_cast<int>(nodes.size());

  // 4. The ends must meet across the road.
  const double first_perp_x = std::cos(nodes[0].beta);
  const double first_perp_y = std::sin(nodes[0].beta);
  const double gx = first_perp_x * (nodes[0].x - nodes[n - 1].x);
  const double gy = first_perp_y * (nodes[0].y - nodes[n - 1].y);
  if (std::sqrt(gx * gx + gy * gy) > Track::kDetailStep) return false;

  // 5. Kerbs on sharp turns: four consecutive heading changes of one sign, each above 0.062 rad;
  // then each flag spreads to the three nodes before it, in place (so flags set at the wrap can
  // spread again when the loop reaches the end).
  std::vector<uint8_t>& border = track->border;
  border.assign(n, 0);
  for (int i = 0; i < n; ++i) {
    bool good = true;
    double oneside = 0;
    for (int neg = 0; neg < Track::kBorderMinCount; ++neg) {
      const double beta1 = nodes[Wrap(i - neg, n)].beta;
      const double beta2 = nodes[Wrap(i - neg - 1, n)].beta;
      good = good && std::abs(beta1 - beta2) > Track::kTurnRate * 0.2;
      oneside += Sign(beta1 - beta2);
    }
    border[i] = good && std::abs(oneside) == Track::kBorderMinCount;
  }
  for (int i = 0; i < n; ++i) {
    for (int neg = 0; neg < Track::kBorderMinCount; ++neg) {
      border[Wrap(i - neg, n)] |= border[i];
    }
  }

  // 6. Tiles from node i - 1 to node i, and their kerbs.
  track->tiles.resize(n);
  track->kerbs.clear();
  const double w = Track::kTrackWidth;
  for (int i = 0; i < n; ++i) {
    const Track::Node& a = nodes[i];
    const Track::Node& b = nodes[Wrap(i - 1, n)];
    const double c1 = std::cos(a.beta), s1 = std::sin(a.beta);
    const double c2 = std::cos(b.beta), s2 = std::sin(b.beta);
    track->tiles[i] = {Vec2d{a.x - w * c1, a.y - w * s1}, Vec2d{a.x + w * c1, a.y + w * s1},
                       Vec2d{b.x + w * c2, b.y + w * s2}, Vec2d{b.x - w * c2, b.y - w * s2}};
    if (border[i]) {
      const double side = Sign(b.beta - a.beta);
      const double in = side * w;
      const double out = side * (w + Track::kBorder);
      track->kerbs.push_back(
          {i,
           {Vec2d{a.x + in * c1, a.y + in * s1}, Vec2d{a.x + out * c1, a.y + out * s1},
            Vec2d{b.x + out * c2, b.y + out * s2}, Vec2d{b.x + in * c2, b.y + in * s2}},
           i % 2 == 1});
    }
  }
  return true;
}

int GenerateCarRacingTrack(std::mt19937_64& rng, CarRacingTrack* track) {
  for (int attempt = 1; attempt <= 1000; ++attempt) {
    if (TryGenerateCarRacingTrack(rng, track)) return attempt;
  }
  throw std::runtime_error("CarRacing: no track after 1000 attempts");
}

}  // namespace rl::envs
