// Drawing of CarRacing's pictures (environments.md 3.10) from a plain description of the scene,
// apart from the Box2D env so that it can be tested on constructed scenes.
//
// The reference draws on a 1000 x 800 surface (world y up, then flipped) and shrinks it to 96 x 96
// with an area-averaging filter (pygame's smoothscale), which is the known bottleneck of the Python
// env. Here every picture is drawn straight at its output size: the output pixel (i, j) covers the
// surface rectangle [i, i + 1) * 1000 / width x [j, j + 1) * 800 / height, and its colour is the
// mean of supersample x supersample point samples on a regular grid inside it. That keeps what the
// area average does to edges and thin lines (a kerb 2 pixels wide, the car 4 x 8 pixels) without
// drawing 800,000 surface pixels. Shapes are painted in the reference's order at each sample,
// so shared edges of adjacent tiles never show seams.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "envs/box2d/car_racing_track.h"
#include "envs/raster.h"

namespace rl::envs {

/// Everything the picture shows, in world units (y up). Built by CarRacing::scene().
struct CarRacingScene {
  static constexpr int kSurfaceWidth = 1000;  // The reference's surface (WINDOW_W x WINDOW_H).
  static constexpr int kSurfaceHeight = 800;

  /// A polygon of up to 8 vertices (Box2D's limit) with its fill colour. Convex in practice; any
  /// polygon is filled by the even-odd rule.
  struct Polygon {
    std::array<Vec2d, 8> vertices{};
    int count = 0;
    Rgb color;
  };

  double t = 0;         // Seconds since the reset started (0.02 after Reset); sets the zoom-in.
  Vec2d hull_position;  // The hull body's origin: the camera centres here.
  double hull_angle = 0;
  Rgb background{102, 204, 102};  // The playfield square.
  Rgb grass{102, 230, 102};       // The lattice of grass squares.
  // Road tiles, each followed by its kerb if it has one, in the reference's order.
  std::vector<Polygon> road;
  // The car in drawing order: each wheel's box (black) and, when visible, its grey tread quad,
  // then the hull's four polygons (204, 0, 0). World coordinates.
  std::vector<Polygon> car;
  // Indicator bar values (environments.md 3.10 step 6).
  double true_speed = 0;                // |hull linear velocity|.
  std::array<double, 4> wheel_omega{};  // Wheel angular speeds (FL, FR, RL, RR).
  double front_joint_angle = 0;         // Steering joint angle of wheel 0.
  double hull_angular_velocity = 0;
  double score = 0;  // The episode's reward so far, shown bottom left as "%04.0f".
};

/// Zoom of the camera at time t: 0.1 * 6 * max(1 - t, 0) + 2.7 * 6 * min(t, 1), from 0.6 at t = 0
/// to 16.2 surface pixels per world unit from t = 1 on.
double CarRacingZoom(double t);

/// Where the world point p lands on the reference's 1000 x 800 surface after the flip (y down):
/// rotated by -hull_angle about the origin, scaled by the zoom, translated so that the hull is at
/// (500, 600).
Vec2d CarRacingSurfacePoint(const CarRacingScene& scene, Vec2d p);

/// The score as the reference prints it, "{:04.0f}": rounded to nearest (ties to even), zero-padded
/// to at least 4 characters, e.g. 12.4 -> "0012", -5.3 -> "-005". The picture shows its digits and
/// minus sign in a seven-segment approximation of the reference's font.
std::string CarRacingScoreText(double score);

/// Draws `scene` at width x height into *rgb (resized; row-major, top row first, 3 bytes per
/// pixel): the playfield, the grass lattice, the road and kerbs, the car, then the indicator bar
/// and the score, each surface pixel mapped as described at the top of this file. supersample in
/// [1, 8]; width and height positive with width * supersample and height * supersample at most
/// 32768 (std::invalid_argument otherwise). Draws only what can be seen; no allocation once *rgb
/// and the scratch buffer have their size (the scratch is thread_local, one byte per sample).
/// O(width * height * supersample^2 + road polygons).
void DrawCarRacing(const CarRacingScene& scene, int width, int height, int supersample,
                   std::vector<uint8_t>* rgb);

}  // namespace rl::envs
