#include "envs/box2d/car_racing_render.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <initializer_list>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "envs/raster.h"
#include "tests/envs/image_testing.h"

namespace rl::envs {
namespace {

using Polygon = CarRacingScene::Polygon;

constexpr Rgb kHullRed{204, 0, 0};
constexpr Rgb kRoad{102, 102, 102};
constexpr Rgb kBackground{102, 204, 102};
constexpr Rgb kGrass{102, 230, 102};
constexpr double kGrassDim = CarRacingTrack::kPlayfield / 20;

Vec2d Rotate(Vec2d p, double angle) {
  const double c = std::cos(angle);
  const double s = std::sin(angle);
  return Vec2d{p.x * c - p.y * s, p.x * s + p.y * c};
}

// p rotated by `angle` about `centre`.
Vec2d RotateAbout(Vec2d p, Vec2d centre, double angle) {
  const Vec2d r = Rotate(Vec2d{p.x - centre.x, p.y - centre.y}, angle);
  return Vec2d{centre.x + r.x, centre.y + r.y};
}

Polygon MakePolygon(std::initializer_list<Vec2d> vertices, Rgb color) {
  Polygon polygon;
  for (const Vec2d& v : vertices) polygon.vertices[polygon.count++] = v;
  polygon.color = color;
  return polygon;
}

// The car of car_dynamics.py (environments.md 3.2) at `position`, turned by `angle`, wheels
// straight: four black wheel boxes, then the four hull polygons.
std::vector<Polygon> MakeCar(Vec2d position, double angle) {
  constexpr double kSize = 0.02;
  const auto place = [&](double x, double y) {
    const Vec2d r = Rotate(Vec2d{x, y}, angle);
    return Vec2d{position.x + r.x, position.y + r.y};
  };
  std::vector<Polygon> car;
  for (const auto& [wx, wy] :
       std::array<std::array<double, 2>, 4>{{{-55, 80}, {55, 80}, {-55, -82}, {55, -82}}}) {
    const double x = wx * kSize;
    const double y = wy * kSize;
    car.push_back(MakePolygon({place(x - 0.28, y - 0.54), place(x + 0.28, y - 0.54),
                               place(x + 0.28, y + 0.54), place(x - 0.28, y + 0.54)},
                              kBlack));
  }
  const std::vector<std::vector<std::array<double, 2>>> hull = {
      {{-60, 130}, {60, 130}, {60, 110}, {-60, 110}},
      {{-15, 120}, {15, 120}, {20, 20}, {-20, 20}},
      {{25, 20}, {50, -10}, {50, -40}, {20, -90}, {-20, -90}, {-50, -40}, {-50, -10}, {-25, 20}},
      {{-50, -120}, {50, -120}, {50, -90}, {-50, -90}}};
  for (const auto& poly : hull) {
    Polygon p;
    for (const auto& [x, y] : poly) p.vertices[p.count++] = place(x * kSize, y * kSize);
    p.color = kHullRed;
    car.push_back(p);
  }
  return car;
}

// A road along the circle of radius `radius` about `centre`, counter-clockwise from angle a0 to
// a1, in tiles of about 3.5 units with the reference's three shades, and a kerb on the outside of
// every tile (white on even tiles, red on odd ones).
std::vector<Polygon> MakeArcRoad(Vec2d centre, double radius, double a0, double a1) {
  constexpr double kHalfWidth = CarRacingTrack::kTrackWidth;
  constexpr double kBorder = CarRacingTrack::kBorder;
  const int tiles = std::max(1, static_cast<int>(std::ceil((a1 - a0) * radius / 3.5)));
  const auto at = [&](double r, double a) {
    return Vec2d{centre.x + r * std::cos(a), centre.y + r * std::sin(a)};
  };
  std::vector<Polygon> road;
  for (int i = 0; i < tiles; ++i) {
    const double b0 = a0 + (a1 - a0) * i / tiles;
    const double b1 = a0 + (a1 - a0) * (i + 1) / tiles;
    const uint8_t shade = static_cast<uint8_t>(102 + 0.01 * (i % 3) * 255);
    road.push_back(MakePolygon({at(radius - kHalfWidth, b0), at(radius + kHalfWidth, b0),
                                at(radius + kHalfWidth, b1), at(radius - kHalfWidth, b1)},
                               Rgb{shade, shade, shade}));
    road.push_back(MakePolygon({at(radius + kHalfWidth, b0), at(radius + kHalfWidth + kBorder, b0),
                                at(radius + kHalfWidth + kBorder, b1), at(radius + kHalfWidth, b1)},
                               i % 2 == 0 ? kWhite : Rgb{255, 0, 0}));
  }
  return road;
}

// A car driving counter-clockwise on an arc road of radius 50 about the origin, at polar angle
// `where`, with the grass lattice in view; every indicator lit and a score.
CarRacingScene MakeDrivingScene(double t, double where) {
  CarRacingScene scene;
  scene.t = t;
  scene.hull_position = Vec2d{50 * std::cos(where), 50 * std::sin(where)};
  scene.hull_angle = where + 0.15;  // Forward (+y body axis) is the tangent, turned a little.
  scene.road = MakeArcRoad({0, 0}, 50, where - 1.2, where + 1.2);
  scene.car = MakeCar(scene.hull_position, scene.hull_angle);
  scene.true_speed = 60;
  scene.wheel_omega = {80, 75, -30, 50};
  scene.front_joint_angle = 0.2;
  scene.hull_angular_velocity = -1.5;
  scene.score = 123.4;
  return scene;
}

Image Draw(const CarRacingScene& scene, int width, int height, int supersample) {
  Image image;
  image.width = width;
  image.height = height;
  DrawCarRacing(scene, width, height, supersample, &image.rgb);
  return image;
}

// The 1000 x 800 surface drawn one sample per pixel, shrunk by area averaging: what the reference
// does (draw, then smoothscale), with our shapes.
Image DrawShrunk(const CarRacingScene& scene, int width, int height) {
  const Image surface = Draw(scene, 1000, 800, 1);
  Image image;
  image.width = width;
  image.height = height;
  ResizeRgbArea(surface.rgb, 1000, 800, width, height, &image.rgb);
  return image;
}

// Mean absolute difference per channel over rows [row_begin, row_end).
double MeanAbsDiff(const Image& a, const Image& b, int row_begin, int row_end) {
  EXPECT_EQ(a.width, b.width);
  EXPECT_EQ(a.height, b.height);
  double sum = 0;
  const std::size_t begin = static_cast<std::size_t>(row_begin) * a.width * 3;
  const std::size_t end = static_cast<std::size_t>(row_end) * a.width * 3;
  for (std::size_t i = begin; i < end; ++i) sum += std::abs(a.rgb[i] - b.rgb[i]);
  return sum / static_cast<double>(end - begin);
}

double MeanAbsDiff(const Image& a, const Image& b) { return MeanAbsDiff(a, b, 0, a.height); }

bool IsReddish(Rgb c) { return c.r > 120 && c.g < 100 && c.b < 100; }

TEST(CarRacingRenderTest, ZoomGrowsFromPointSixToSixteenPointTwoInTheFirstSecond) {
  EXPECT_DOUBLE_EQ(CarRacingZoom(0), 0.6);
  EXPECT_DOUBLE_EQ(CarRacingZoom(0.02), 0.6 * 0.98 + 16.2 * 0.02);  // 0.912 after Reset.
  EXPECT_NEAR(CarRacingZoom(0.02), 0.912, 1e-12);
  EXPECT_DOUBLE_EQ(CarRacingZoom(0.5), 0.3 + 8.1);
  EXPECT_DOUBLE_EQ(CarRacingZoom(1), 16.2);
  EXPECT_DOUBLE_EQ(CarRacingZoom(2), 16.2);
}

TEST(CarRacingRenderTest, SurfacePointPutsTheHullAt500x600WithForwardUp) {
  for (const double t : {0.02, 0.5, 1.0, 3.0}) {
    for (const double angle : {0.0, 0.4, -2.0, 3.0}) {
      for (const Vec2d hull : {Vec2d{0, 0}, Vec2d{120.5, -37.25}, Vec2d{-300, 250}}) {
        CarRacingScene scene;
        scene.t = t;
        scene.hull_position = hull;
        scene.hull_angle = angle;
        const double zoom = CarRacingZoom(t);
        const Vec2d origin = CarRacingSurfacePoint(scene, hull);
        EXPECT_NEAR(origin.x, 500, 1e-9);
        EXPECT_NEAR(origin.y, 600, 1e-9);
        // The car's forward (body +y) is up on screen, its right (body +x) is right.
        const Vec2d forward = Rotate({0, 1}, angle);
        const Vec2d ahead = CarRacingSurfacePoint(scene, {hull.x + forward.x, hull.y + forward.y});
        EXPECT_NEAR(ahead.x, 500, 1e-9);
        EXPECT_NEAR(ahead.y, 600 - zoom, 1e-9);
        const Vec2d right = Rotate({1, 0}, angle);
        const Vec2d beside = CarRacingSurfacePoint(scene, {hull.x + right.x, hull.y + right.y});
        EXPECT_NEAR(beside.x, 500 + zoom, 1e-9);
        EXPECT_NEAR(beside.y, 600, 1e-9);
      }
    }
  }
}

TEST(CarRacingRenderTest, CarShowsAroundPixel48x72) {
  for (const double angle : {0.0, 0.7, -2.5}) {
    CarRacingScene scene;
    scene.t = 1;
    scene.hull_position = {10, 20};
    scene.hull_angle = angle;
    scene.car = MakeCar(scene.hull_position, angle);
    const Image image = Draw(scene, 96, 96, 4);
    ASSERT_EQ(image.rgb.size(), 96u * 96u * 3u);
    // The camera turns with the car, so the car points up whatever the angle. The hull is 2.4 x 5
    // units, 39 x 81 surface pixels or 3.7 x 9.7 output pixels, its origin at (48, 72): only the
    // middle polygon (2 units wide) covers whole pixels.
    const Blob red = FindColor(image, kHullRed);
    EXPECT_GE(red.count, 4) << angle;
    EXPECT_NEAR(red.mean_x, 48, 1.0) << angle;
    EXPECT_NEAR(red.mean_y, 72, 2.0) << angle;
    int red_columns_min = 96, red_columns_max = -1, red_rows_min = 96, red_rows_max = -1;
    for (int y = 0; y < 96; ++y) {
      for (int x = 0; x < 96; ++x) {
        if (!IsReddish(image.at(x, y))) continue;
        red_columns_min = std::min(red_columns_min, x);
        red_columns_max = std::max(red_columns_max, x);
        red_rows_min = std::min(red_rows_min, y);
        red_rows_max = std::max(red_rows_max, y);
      }
    }
    // Hull x in [-1.2, 1.2] units: surface x 480.6-519.4, columns 46.1-49.9; y in [-2.4, 2.6]:
    // surface y 557.9-638.9, rows 66.9-76.7.
    EXPECT_GE(red_columns_min, 46) << angle;
    EXPECT_LE(red_columns_max, 49) << angle;
    EXPECT_GE(red_rows_min, 66) << angle;
    EXPECT_LE(red_rows_max, 76) << angle;
    // The front wheels (0.56 x 1.08 units at x = -+1.1, y = 1.6; columns 45.9-46.7 and 49.3-50.1):
    // dark pixels either side of the hull, less than a pixel wide, so blended.
    for (const int x : {46, 49}) {
      const Rgb wheel = image.at(x, 68);
      EXPECT_LT(wheel.g, 80) << angle << " " << x;
      EXPECT_LT(wheel.r, 50) << angle << " " << x;
    }
    EXPECT_EQ(image.at(30, 40), kBackground) << angle;
  }
}

TEST(CarRacingRenderTest, TheImageTurnsWithTheCar) {
  // The grass in the background's colour: the lattice is fixed in the world and would turn.
  CarRacingScene scene = MakeDrivingScene(1, 0.3);
  scene.grass = scene.background;
  const Image image = Draw(scene, 96, 96, 4);

  // Turning the world and the car together about the hull: the same picture.
  constexpr double kTurn = 0.9;
  CarRacingScene turned = scene;
  turned.hull_angle += kTurn;
  for (std::vector<Polygon>* layer : {&turned.road, &turned.car}) {
    for (Polygon& p : *layer) {
      for (int i = 0; i < p.count; ++i) {
        p.vertices[i] = RotateAbout(p.vertices[i], scene.hull_position, kTurn);
      }
    }
  }
  const Image same = Draw(turned, 96, 96, 4);
  const double turned_diff = MeanAbsDiff(image, same);
  EXPECT_LT(turned_diff, 0.1);

  // Turning only the car: the road turns on screen the other way.
  CarRacingScene car_only = scene;
  car_only.hull_angle += kTurn;
  car_only.car = MakeCar(scene.hull_position, car_only.hull_angle);
  const Image other = Draw(car_only, 96, 96, 4);
  const double car_only_diff = MeanAbsDiff(image, other);
  EXPECT_GT(car_only_diff, 5.0);
  // ... and the car still points up at (48, 72).
  EXPECT_NEAR(FindColor(other, kHullRed).mean_x, 48, 1.0);
  std::printf("turned together: mean abs diff %.4f; car only: %.3f\n", turned_diff, car_only_diff);
}

TEST(CarRacingRenderTest, OutsideThePlayfieldIsBlack) {
  CarRacingScene scene;
  scene.t = 1;
  scene.hull_position = {CarRacingTrack::kPlayfield - 3, 0};  // The edge is 3 units to the right.
  const Image image = Draw(scene, 96, 96, 4);
  // Surface x of the edge: 500 + 3 * 16.2 = 548.6, column 52.7.
  for (int y = 0; y < 84; ++y) {
    EXPECT_NE(image.at(51, y), kBlack) << y;
    EXPECT_EQ(image.at(54, y), kBlack) << y;
    EXPECT_EQ(image.at(95, y), kBlack) << y;
  }
}

TEST(CarRacingRenderTest, GrassLatticeCoversOneCellInFour) {
  CarRacingScene scene;
  scene.t = 1;
  // The centre of the grass cell [0, 16.7]^2; the cells right of and above it are not grass.
  scene.hull_position = {kGrassDim / 2, kGrassDim / 2};
  const Image image = Draw(scene, 96, 96, 4);
  EXPECT_EQ(image.at(48, 72), kGrass);
  // 16.7 units = 270 surface pixels = 25.9 columns or 32.4 rows.
  EXPECT_EQ(image.at(48 + 26, 72), kBackground);
  EXPECT_EQ(image.at(48, 72 - 32), kBackground);
  EXPECT_EQ(image.at(48 + 26, 72 - 32), kBackground);
  // Cell (2, 0) starts 25 units (405 pixels) to the right: column 86.9.
  EXPECT_EQ(image.at(86, 72), kBackground);
  EXPECT_EQ(image.at(88, 72), kGrass);
}

TEST(CarRacingRenderTest, AdjacentTilesLeaveNoSeams) {
  // A fan of thin tiles sharing edges, turned, in one colour over the background: no sample
  // between them may show the background.
  CarRacingScene scene;
  scene.t = 1;
  scene.hull_angle = 0.37;
  scene.road = MakeArcRoad({-3, -20}, 25, 0.2, 2.2);
  for (Polygon& p : scene.road) p.color = kRoad;
  const Image image = Draw(scene, 1000, 800, 1);
  // Scan each row between the first and last road pixel: no background in between, as long as
  // the row stays inside the road band (checked by the arc's convexity: count transitions).
  int rows_checked = 0;
  for (int y = 0; y < 700; ++y) {
    int transitions = 0;
    Rgb previous = image.at(0, y);
    for (int x = 1; x < 1000; ++x) {
      const Rgb c = image.at(x, y);
      if ((c == kRoad) != (previous == kRoad)) ++transitions;
      previous = c;
    }
    // A horizontal line crosses the band at most twice: four transitions, or two.
    EXPECT_LE(transitions, 4) << y;
    if (transitions > 0) ++rows_checked;
  }
  EXPECT_GT(rows_checked, 300);
}

TEST(CarRacingRenderTest, IndicatorBarIsBlackWithoutIndicators) {
  CarRacingScene scene = MakeDrivingScene(1, 0.3);
  scene.true_speed = 0;
  scene.wheel_omega = {0, 0, 0, 0};
  scene.front_joint_angle = 0;
  scene.hull_angular_velocity = 5e-5;  // Below the reference's threshold.
  const Image image = Draw(scene, 96, 96, 4);
  // Rows 84-95 are the bar (surface y >= 700); the score is in columns 1-10.
  for (int y = 84; y < 96; ++y) {
    for (int x = 11; x < 96; ++x) ASSERT_EQ(image.at(x, y), kBlack) << x << "," << y;
  }
  // The score "0123": white-ish pixels in the text area only.
  int bright = 0;
  for (int y = 84; y < 96; ++y) {
    for (int x = 0; x < 11; ++x) {
      if (image.at(x, y).g > 60) {
        ++bright;
        EXPECT_GE(y, 88) << x;
        EXPECT_LE(y, 91) << x;
      }
    }
  }
  EXPECT_GE(bright, 8);
  // The row above the bar is the world.
  EXPECT_NE(image.at(60, 83), kBlack);
}

// Non-black pixels in columns [x0, x1) of the bar's rows.
int LitPixels(const Image& image, int x0, int x1) {
  int lit = 0;
  for (int y = 84; y < 96; ++y) {
    for (int x = x0; x < x1; ++x) lit += image.at(x, y) == kBlack ? 0 : 1;
  }
  return lit;
}

TEST(CarRacingRenderTest, SpeedBarGrowsWithSpeed) {
  CarRacingScene scene;
  scene.t = 1;
  std::vector<int> lit;
  for (const double speed : {0.0, 20.0, 50.0, 100.0}) {
    scene.true_speed = speed;
    const Image image = Draw(scene, 96, 96, 4);
    // Slot 5: surface x in [125, 150), columns 12.0 to 14.4.
    lit.push_back(LitPixels(image, 12, 15));
    EXPECT_EQ(LitPixels(image, 11, 12), 0) << speed;
    EXPECT_EQ(LitPixels(image, 15, 96), 0) << speed;
    // From y = 780 (row 93.6) up by 0.4 * speed pixels.
    if (speed == 100) {
      EXPECT_EQ(image.at(12, 90), kWhite);
      EXPECT_EQ(image.at(13, 92), kWhite);
      EXPECT_EQ(image.at(13, 87), kBlack);  // 740 is row 88.8.
      EXPECT_EQ(image.at(13, 94), kBlack);
    }
  }
  EXPECT_EQ(lit[0], 0);
  EXPECT_LT(lit[1], lit[2]);
  EXPECT_LT(lit[2], lit[3]);
}

TEST(CarRacingRenderTest, WheelSteeringAndGyroIndicators) {
  constexpr Rgb kFront{0, 0, 255};
  constexpr Rgb kRear{51, 0, 255};
  constexpr Rgb kGreen{0, 255, 0};
  constexpr Rgb kRed{255, 0, 0};
  CarRacingScene scene;
  scene.t = 1;
  scene.wheel_omega = {150, 0, 0, -100};
  scene.front_joint_angle = 0.3;       // Steering left: the bar grows left from x = 500.
  scene.hull_angular_velocity = -2.0;  // v = 1.6: right from x = 750 to 790.
  Image image = Draw(scene, 96, 96, 4);
  // Slot 7 (x 175-200, columns 16.8-19.2), upwards 30 px from 780: rows 90-93 full.
  EXPECT_EQ(image.at(17, 91), kFront);
  EXPECT_EQ(image.at(18, 92), kFront);
  EXPECT_EQ(image.at(17, 89), kBlack);
  EXPECT_EQ(LitPixels(image, 20, 24), 0);  // Slots 8 and 9 are zero.
  // Slot 10 (x 250-275, columns 24-26.4) negative: downwards from 780 to the bottom edge.
  EXPECT_EQ(image.at(24, 95), kRear);
  EXPECT_EQ(image.at(25, 94), kRear);
  EXPECT_EQ(image.at(25, 92), kBlack);
  // Steering: x in [425, 500), columns 40.8-48, y in [720, 760), rows 86.4-91.2.
  for (int x = 41; x < 48; ++x) EXPECT_EQ(image.at(x, 88), kGreen) << x;
  EXPECT_EQ(image.at(49, 88), kBlack);
  EXPECT_EQ(image.at(39, 88), kBlack);
  // Gyro: columns 72-75.8.
  for (int x = 72; x < 75; ++x) EXPECT_EQ(image.at(x, 89), kRed) << x;
  EXPECT_EQ(image.at(71, 89), kBlack);
  EXPECT_EQ(image.at(77, 89), kBlack);

  // The other way round.
  scene.front_joint_angle = -0.3;
  scene.hull_angular_velocity = 2.0;
  image = Draw(scene, 96, 96, 4);
  for (int x = 49; x < 55; ++x) EXPECT_EQ(image.at(x, 88), kGreen) << x;
  EXPECT_EQ(image.at(46, 88), kBlack);
  for (int x = 69; x < 72; ++x) EXPECT_EQ(image.at(x, 89), kRed) << x;
  EXPECT_EQ(image.at(73, 89), kBlack);
}

TEST(CarRacingRenderTest, ScoreTextIsFormattedLikeTheReference) {
  EXPECT_EQ(CarRacingScoreText(0), "0000");
  EXPECT_EQ(CarRacingScoreText(12.4), "0012");
  EXPECT_EQ(CarRacingScoreText(12.6), "0013");
  EXPECT_EQ(CarRacingScoreText(-5.3), "-005");
  EXPECT_EQ(CarRacingScoreText(-0.3), "-000");
  EXPECT_EQ(CarRacingScoreText(2.5), "0002");  // Ties to even.
  EXPECT_EQ(CarRacingScoreText(3.5), "0004");
  EXPECT_EQ(CarRacingScoreText(931.7), "0932");
  EXPECT_EQ(CarRacingScoreText(12345.2), "12345");
}

TEST(CarRacingRenderTest, ScoreTextShowsTheDigits) {
  CarRacingScene scene;
  scene.t = 1;
  const auto text_area = [&](double score) {
    scene.score = score;
    const Image image = Draw(scene, 1000, 800, 1);
    // Count white pixels in the text box, and check it stays in it.
    int white = 0;
    for (int y = 700; y < 800; ++y) {
      for (int x = 0; x < 125; ++x) {
        if (image.at(x, y) == kWhite) {
          ++white;
          EXPECT_GE(x, 10);
          EXPECT_LT(x, 110);
          EXPECT_GE(y, 735);
          EXPECT_LT(y, 765);
        }
      }
    }
    return white;
  };
  // Seven segments: "8888" lights all 28 segments, "1111" 8 of them, "-111" 6.
  const int eights = text_area(8888);
  const int ones = text_area(1111);
  const int minus = text_area(-111);
  EXPECT_GT(eights, 2 * ones);
  EXPECT_LT(minus, ones);
  EXPECT_GT(minus, 0);
}

// The key fidelity check: drawing straight at 96 x 96 with supersampling approximates drawing the
// reference's 1000 x 800 surface and shrinking it by area averaging.
TEST(CarRacingRenderTest, SupersampledDrawingMatchesTheShrunkSurface) {
  struct Case {
    const char* name;
    CarRacingScene scene;
  };
  const std::vector<Case> cases = {{"driving", MakeDrivingScene(1, 0.3)},
                                   {"zooming in", MakeDrivingScene(0.3, 2.0)},
                                   {"after reset", MakeDrivingScene(0.02, -1.0)}};
  for (const Case& c : cases) {
    const Image reference = DrawShrunk(c.scene, 96, 96);
    std::array<double, 5> diff{};
    for (const int ss : {1, 2, 4}) diff[ss] = MeanAbsDiff(reference, Draw(c.scene, 96, 96, ss));
    const double above_bar = MeanAbsDiff(reference, Draw(c.scene, 96, 96, 4), 0, 84);
    std::printf(
        "%-12s mean abs diff vs shrunk 1000x800: ss1 %.3f  ss2 %.3f  ss4 %.3f (above bar %.3f)\n",
        c.name, diff[1], diff[2], diff[4], above_bar);
    RecordProperty(std::string(c.name) + " ss4", std::to_string(diff[4]));
    EXPECT_LT(diff[4], 1.0) << c.name;
    EXPECT_LT(diff[2], 2.0) << c.name;
    // Without supersampling edges are all or nothing: clearly worse.
    EXPECT_GT(diff[1], 2 * diff[4]) << c.name;
  }

  // The video frame: 600 x 400 at supersample 2.
  const CarRacingScene scene = MakeDrivingScene(1, 0.3);
  const double video = MeanAbsDiff(DrawShrunk(scene, 600, 400), Draw(scene, 600, 400, 2));
  std::printf("600x400 ss2 mean abs diff vs shrunk 1000x800: %.3f\n", video);
  EXPECT_LT(video, 1.0);
}

TEST(CarRacingRenderTest, BadArgumentsThrow) {
  const CarRacingScene scene;
  std::vector<uint8_t> rgb;
  EXPECT_THROW(DrawCarRacing(scene, 0, 96, 4, &rgb), std::invalid_argument);
  EXPECT_THROW(DrawCarRacing(scene, 96, -1, 4, &rgb), std::invalid_argument);
  EXPECT_THROW(DrawCarRacing(scene, 96, 96, 0, &rgb), std::invalid_argument);
  EXPECT_THROW(DrawCarRacing(scene, 96, 96, 9, &rgb), std::invalid_argument);
  EXPECT_THROW(DrawCarRacing(scene, 5000, 96, 8, &rgb), std::invalid_argument);
  EXPECT_NO_THROW(DrawCarRacing(scene, 1, 1, 8, &rgb));
  EXPECT_EQ(rgb.size(), 3u);
}

TEST(CarRacingRenderTest, NonFiniteShapesAreSkipped) {
  CarRacingScene scene = MakeDrivingScene(1, 0.3);
  const Image image = Draw(scene, 96, 96, 4);
  Polygon broken = scene.road.front();
  broken.vertices[1].x = std::nan("");
  scene.road.push_back(broken);
  broken.vertices[1].x = INFINITY;
  scene.car.push_back(broken);
  scene.true_speed = NAN;  // Not drawn, as |NaN| > 1e-4 is false.
  const Image same = Draw(scene, 96, 96, 4);
  // Only the speed bar may differ.
  EXPECT_EQ(MeanAbsDiff(image, same, 0, 84), 0);
  EXPECT_EQ(LitPixels(same, 12, 15), 0);
}

TEST(CarRacingRenderTest, SameSceneGivesTheSameBytes) {
  const CarRacingScene scene = MakeDrivingScene(0.7, 1.1);
  std::vector<uint8_t> first;
  DrawCarRacing(scene, 96, 96, 4, &first);
  const uint8_t* data = first.data();
  // Another size and supersample in between reuses the scratch.
  std::vector<uint8_t> other;
  DrawCarRacing(MakeDrivingScene(1, 2), 600, 400, 2, &other);
  DrawCarRacing(scene, 96, 96, 4, &first);
  EXPECT_EQ(first.data(), data);  // Drawn in place.
  std::vector<uint8_t> second;
  DrawCarRacing(scene, 96, 96, 4, &second);
  EXPECT_EQ(first, second);
}

}  // namespace
}  // namespace rl::envs
