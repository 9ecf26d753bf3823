// CarRacing's procedural track (environments.md 3.5), apart from the Box2D env so that it can be
// generated, inspected and tested without physics. Everything is computed in double precision,
// as the reference computes it in Python floats.
#pragma once

#include <array>
#include <cstdint>
#include <random>
#include <vector>

namespace rl::envs {

/// A point of the plane in world units (CarRacing's "metres": SCALE 6 pixels of the reference's
/// 1000 x 800 surface at zoom 1).
struct Vec2d {
  double x = 0;
  double y = 0;
};

/// A generated track: one node per road tile, in driving order (counter-clockwise around the
/// origin). Tile i spans from node i - 1 to node i (node -1 is the last one), so the car, which
/// starts at node 0 facing node 1, starts on tile 0 and tile 1.
struct CarRacingTrack {
  // Constants of the reference (environments.md 3.1).
  static constexpr double kScale = 6.0;
  static constexpr double kTrackRad = 900.0 / kScale;  // 150
  static constexpr double kPlayfield =
      2000.0 / kScale;  // 333.33: the car leaves it at |x| or |y| above this
  static constexpr double kDetailStep = 21.0 / kScale;  // 3.5
  static constexpr double kTurnRate = 0.31;
  static constexpr double kTrackWidth = 40.0 / kScale;  // 6.67, the half-width of the road
  static constexpr double kBorder = 8.0 / kScale;       // 1.33, the width of a kerb
  static constexpr int kBorderMinCount = 4;
  static constexpr int kCheckpoints = 12;

  struct Node {
    double alpha = 0;  // Polar angle of the walk when it placed the node.
    double beta = 0;   // Heading of the road at the node (the car faces beta + pi / 2).
    double x = 0;
    double y = 0;
  };
  /// A kerb: the visual strip (no physics) on the outside of a sharp turn, beside its tile.
  struct Kerb {
    int tile = 0;                 // The tile it belongs to (drawn right after that tile).
    std::array<Vec2d, 4> quad{};  // [b1_l, b1_r, b2_r, b2_l] as the reference orders them.
    bool red = false;             // Odd tile index: red (255, 0, 0); even: white.
  };

  std::vector<Node> nodes;
  std::vector<std::array<Vec2d, 4>> tiles;  // [road1_l, road1_r, road2_r, road2_l] per node.
  std::vector<uint8_t> border;              // Whether node i has a kerb (after propagation).
  std::vector<Kerb> kerbs;                  // In tile order.

  int size() const { return static_cast<int>(nodes.size()); }
  /// Sum of the distances between consecutive nodes, closing the loop.
  double Length() const;
};

/// One generation attempt (environments.md 3.5): draws 24 doubles from `rng` (noise then radius
/// for each of the 12 checkpoints, numpy's uniform from 53 bits), walks, cuts one lap and checks
/// the glue. Returns false, leaving *track unspecified, when the lap cannot be cut or the ends do
/// not meet; the reference then retries with fresh draws. O(walk length), at most 2,500 nodes.
bool TryGenerateCarRacingTrack(std::mt19937_64& rng, CarRacingTrack* track);

/// Attempts until one succeeds, as the reference's reset does; returns the number of attempts
/// (about 8 % of attempts fail). Throws std::runtime_error after 1,000 failures in a row, which
/// no seed has been seen to reach.
int GenerateCarRacingTrack(std::mt19937_64& rng, CarRacingTrack* track);

}  // namespace rl::envs
