// CarRacing's track generation (environments.md 3.5): the statistics of many tracks, their shape,
// and determinism.
#include "envs/box2d/car_racing_track.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "envs/rng.h"

namespace rl::envs {
namespace {

CarRacingTrack TrackOf(uint64_t seed, int* attempts = nullptr) {
  EnvRng rng;
  rng.Seed(seed);
  CarRacingTrack track;
  const int n = GenerateCarRacingTrack(rng, &track);
  if (attempts != nullptr) *attempts = n;
  return track;
}

// Whether segments ab and cd cross (proper intersection; nearly collinear segments of a straight
// stretch do not count).
bool Cross(Vec2d a, Vec2d b, Vec2d c, Vec2d d) {
  const auto orient = [](Vec2d p, Vec2d q, Vec2d r) {
    return (q.x - p.x) * (r.y - p.y) - (q.y - p.y) * (r.x - p.x);
  };
  const double d1 = orient(a, b, c), d2 = orient(a, b, d);
  const double d3 = orient(c, d, a), d4 = orient(c, d, b);
  return d1 * d2 < -1e-6 && d3 * d4 < -1e-6;
}

TEST(CarRacingTrackTest, TileCountsAndFailedAttemptsMatchTheReferencesStatistics) {
  // environments.md 3.9: median about 290 tiles, 5-95 % range 260-330, extremes 227-379 over 400
  // tracks; about 8 % of attempts fail.
  std::vector<int> sizes;
  int attempts = 0;
  for (uint64_t seed = 0; seed < 400; ++seed) {
    int a = 0;
    sizes.push_back(TrackOf(seed, &a).size());
    attempts += a;
  }
  std::sort(sizes.begin(), sizes.end());
  EXPECT_GE(sizes[200], 280);
  EXPECT_LE(sizes[200], 300);
  EXPECT_GE(sizes[20], 250);
  EXPECT_LE(sizes[380], 340);
  EXPECT_GE(sizes.front(), 220);
  EXPECT_LE(sizes.back(), 390);
  const double failed = 1.0 - 400.0 / attempts;
  EXPECT_GT(failed, 0.03);
  EXPECT_LT(failed, 0.15);
}

TEST(CarRacingTrackTest, EachAttemptDrawsTwentyFourNumbers) {
  EnvRng rng;
  rng.Seed(11);
  EnvRng copy = rng;
  CarRacingTrack track;
  TryGenerateCarRacingTrack(rng, &track);
  copy.discard(24);
  EXPECT_EQ(rng(), copy());
}

TEST(CarRacingTrackTest, TrackIsAClosedLoopOfEvenStepsAroundTheOrigin) {
  for (uint64_t seed = 0; seed < 50; ++seed) {
    const CarRacingTrack track = TrackOf(seed);
    const int n = track.size();
    ASSERT_EQ(track.tiles.size(), static_cast<std::size_t>(n));
    ASSERT_EQ(track.border.size(), static_cast<std::size_t>(n));
    double turned = 0;
    for (int i = 1; i < n; ++i) {
      const auto& a = track.nodes[i - 1];
      const auto& b = track.nodes[i];
      EXPECT_NEAR(std::hypot(b.x - a.x, b.y - a.y), CarRacingTrack::kDetailStep, 1e-9);
      turned += std::atan2(a.x * b.y - a.y * b.x, a.x * b.x + a.y * b.y);
    }
    // The ends meet: the gap is at most a few steps (the glue check bounds its sideways part).
    const auto& first = track.nodes.front();
    const auto& last = track.nodes.back();
    EXPECT_LT(std::hypot(first.x - last.x, first.y - last.y), 3 * CarRacingTrack::kDetailStep)
        << "seed " << seed;
    // One counter-clockwise turn around the origin, and inside the playfield.
    EXPECT_NEAR(turned, 2 * M_PI, 0.2) << "seed " << seed;
    for (const auto& node : track.nodes) {
      EXPECT_LT(std::max(std::abs(node.x), std::abs(node.y)), CarRacingTrack::kPlayfield);
    }
    EXPECT_NEAR(track.Length(), n * CarRacingTrack::kDetailStep, 3 * CarRacingTrack::kDetailStep);
  }
}

TEST(CarRacingTrackTest, CentreLineRarelyCrossesItself) {
  // The reference has no rule against a crossing; the walk towards checkpoints at rising angles
  // makes one rare. Count tracks whose centre line crosses itself.
  int crossing = 0;
  for (uint64_t seed = 0; seed < 100; ++seed) {
    const CarRacingTrack track = TrackOf(seed);
    const int n = track.size();
    bool crosses = false;
    for (int i = 0; i < n && !crosses; ++i) {
      const Vec2d a{track.nodes[i].x, track.nodes[i].y};
      const Vec2d b{track.nodes[(i + 1) % n].x, track.nodes[(i + 1) % n].y};
      for (int j = i + 2; j < n && !crosses; ++j) {
        if (i + n - j <= 3) continue;  // Neighbours across the seam, where the lap was cut.
        const Vec2d c{track.nodes[j].x, track.nodes[j].y};
        const Vec2d d{track.nodes[(j + 1) % n].x, track.nodes[(j + 1) % n].y};
        crosses = Cross(a, b, c, d);
      }
    }
    crossing += crosses;
  }
  EXPECT_LE(crossing, 2);
}

TEST(CarRacingTrackTest, TilesJoinNodesAndKerbsSitOnSharpTurns) {
  const CarRacingTrack track = TrackOf(7);
  const int n = track.size();
  for (int i = 0; i < n; ++i) {
    const auto& node = track.nodes[i];
    const auto& tile = track.tiles[i];
    // road1_l and road1_r straddle node i at the half-width.
    EXPECT_NEAR((tile[0].x + tile[1].x) / 2, node.x, 1e-9);
    EXPECT_NEAR((tile[0].y + tile[1].y) / 2, node.y, 1e-9);
    EXPECT_NEAR(std::hypot(tile[1].x - tile[0].x, tile[1].y - tile[0].y),
                2 * CarRacingTrack::kTrackWidth, 1e-9);
    // road2 is node i - 1's edge, shared with the previous tile: no gap between tiles.
    const auto& previous = track.tiles[(i + n - 1) % n];
    EXPECT_NEAR(tile[3].x, previous[0].x, 1e-12);
    EXPECT_NEAR(tile[2].y, previous[1].y, 1e-12);
  }
  ASSERT_FALSE(track.kerbs.empty());
  int flagged = 0;
  for (int i = 0; i < n; ++i) flagged += track.border[i];
  EXPECT_EQ(static_cast<int>(track.kerbs.size()), flagged);
  for (const auto& kerb : track.kerbs) {
    EXPECT_TRUE(track.border[kerb.tile]);
    EXPECT_EQ(kerb.red, kerb.tile % 2 == 1);
    // The strip lies beside the road, from the half-width out by the border width.
    const auto& node = track.nodes[kerb.tile];
    EXPECT_NEAR(std::hypot(kerb.quad[0].x - node.x, kerb.quad[0].y - node.y),
                CarRacingTrack::kTrackWidth, 1e-9);
    EXPECT_NEAR(std::hypot(kerb.quad[1].x - node.x, kerb.quad[1].y - node.y),
                CarRacingTrack::kTrackWidth + CarRacingTrack::kBorder, 1e-9);
  }
  // Kerbs come in runs of at least four: a flag spreads to the three nodes before it.
  for (int i = 0; i < n; ++i) {
    if (track.border[i] && !track.border[(i + 1) % n]) {
      for (int k = 0; k < CarRacingTrack::kBorderMinCount; ++k) {
        EXPECT_TRUE(track.border[(i - k + n) % n]) << "node " << i - k;
      }
    }
  }
}

TEST(CarRacingTrackTest, SameSeedSameTrackOtherSeedOtherTrack) {
  const CarRacingTrack a = TrackOf(42);
  const CarRacingTrack b = TrackOf(42);
  const CarRacingTrack c = TrackOf(43);
  ASSERT_EQ(a.size(), b.size());
  for (int i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a.nodes[i].x, b.nodes[i].x);
    EXPECT_EQ(a.nodes[i].beta, b.nodes[i].beta);
  }
  EXPECT_TRUE(a.size() != c.size() || a.nodes[10].x != c.nodes[10].x);
}

}  // namespace
}  // namespace rl::envs
