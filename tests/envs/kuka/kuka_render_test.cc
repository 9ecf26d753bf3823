#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "envs/kuka/kuka_camera.h"
#include "envs/kuka/kuka_diverse_object_env.h"
#include "envs/kuka/kuka_objects.h"
#include "envs/kuka/kuka_renderer.h"
#include "envs/kuka/kuka_scene.h"
#include "tests/envs/image_testing.h"

namespace rl::envs::kuka {
namespace {

bool IsWhite(const std::vector<uint8_t>& rgb, int i) {
  return rgb[3 * i] == 255 && rgb[3 * i + 1] == 255 && rgb[3 * i + 2] == 255;
}

// Luma of pixel i in grey levels (0..255); Luma is linear, so the colour's weights apply as is.
double PixelLuma(const std::vector<uint8_t>& rgb, int i) {
  return Luma({static_cast<float>(rgb[3 * i]), static_cast<float>(rgb[3 * i + 1]),
               static_cast<float>(rgb[3 * i + 2])});
}

int CountDifferentPixels(const std::vector<uint8_t>& a, const std::vector<uint8_t>& b) {
  int n = 0;
  for (std::size_t i = 0; i + 2 < a.size(); i += 3) {
    if (a[i] != b[i] || a[i + 1] != b[i + 1] || a[i + 2] != b[i + 2]) ++n;
  }
  return n;
}

TEST(KukaRenderTest, RendersTheNativeSizeAndAnyRequestedSize) {
  KukaDiverseObjectEnv env;
  env.Reset(1);
  const Image image = Rendered(env);
  EXPECT_EQ(image.width, 48);
  EXPECT_EQ(image.height, 48);
  ASSERT_EQ(image.rgb.size(), 48u * 48 * 3);
  // The camera looks down at the tray and table: no background left in the middle.
  EXPECT_FALSE(IsWhite(image.rgb, 24 * 48 + 24));
  std::vector<uint8_t> rgb;
  env.RenderSized(160, 120, &rgb);
  EXPECT_EQ(rgb.size(), 160u * 120 * 3);
  EXPECT_THROW(env.RenderSized(0, 10, &rgb), std::invalid_argument);
  // llvmpipe runs on one thread unless the user chose otherwise before the first context.
  ASSERT_NE(std::getenv("LP_NUM_THREADS"), nullptr);
}

TEST(KukaRenderTest, ImageChangesWhenTheArmMoves) {
  KukaDiverseObjectEnv env;
  env.Reset(2);
  const Image before = Rendered(env);
  env.Step(rl::envs::DiscreteAction(2));  // +x and down.
  EXPECT_GT(CountDifferentPixels(before.rgb, Rendered(env).rgb), 20);
}

TEST(KukaRenderTest, ImageChangesWhereAnObjectIsAdded) {
  KukaScene scene;
  scene.AddArm();
  KukaRenderer renderer;
  const CameraParams camera;
  std::vector<DrawItem> items;
  std::vector<uint8_t> empty, with_object;
  scene.CollectDrawItems(&items);
  renderer.Render(camera, items, 96, 96, &empty);
  const ObjectShape shape = GenerateObject(3);
  scene.AddObject(shape, Eigen::Vector3d(0.6, 0.05, -0.1), 0.5);
  scene.CollectDrawItems(&items);
  renderer.Render(camera, items, 96, 96, &with_object);
  // The pixel under the object's centre changed, and a blob of pixels around it.
  const Eigen::Vector2d p = ProjectToPixel(camera, 96, 96, scene.ObjectPose(0).translation());
  const int i = static_cast<int>(p.y()) * 96 + static_cast<int>(p.x());
  EXPECT_NE(std::vector<uint8_t>(empty.begin() + 3 * i, empty.begin() + 3 * i + 3),
            std::vector<uint8_t>(with_object.begin() + 3 * i, with_object.begin() + 3 * i + 3));
  EXPECT_GT(CountDifferentPixels(empty, with_object), 20);
}

TEST(KukaRenderTest, GripperAppearsWhereTheCameraModelProjectsIt) {
  // Golden-free: draw the gripper alone and compare its pixels with the projection of its mesh
  // vertices through ProjectToPixel, in two arm poses and two camera perturbations.
  KukaDiverseObjectEnv env;
  KukaRenderer renderer;
  constexpr int kSize = 96;
  for (uint64_t seed : {3, 4}) {
    env.Reset(seed);
    for (int move = 0; move < 2; ++move) {
      if (move == 1) env.Step(rl::envs::DiscreteAction(seed == 3 ? 4 : 1));
      std::vector<DrawItem> items;
      env.scene().CollectDrawItems(&items);
      std::erase_if(items, [](const DrawItem& d) { return d.group != DrawGroup::kGripper; });
      std::vector<uint8_t> rgb;
      renderer.Render(env.camera(), items, kSize, kSize, &rgb);
      // Bounding box of the drawn pixels.
      int x0 = kSize, y0 = kSize, x1 = -1, y1 = -1;
      for (int y = 0; y < kSize; ++y) {
        for (int x = 0; x < kSize; ++x) {
          if (IsWhite(rgb, y * kSize + x)) continue;
          x0 = std::min(x0, x), x1 = std::max(x1, x), y0 = std::min(y0, y), y1 = std::max(y1, y);
        }
      }
      ASSERT_GE(x1, 0) << "gripper not visible";
      // Bounding box of the projected vertices.
      double px0 = 1e9, py0 = 1e9, px1 = -1e9, py1 = -1e9;
      for (const DrawItem& d : items) {
        for (int v = 0; v < d.mesh->num_vertices(); ++v) {
          const Eigen::Vector3d local(d.mesh->positions[3 * v], d.mesh->positions[3 * v + 1],
                                      d.mesh->positions[3 * v + 2]);
          const Eigen::Vector2d p = ProjectToPixel(env.camera(), kSize, kSize, d.transform * local);
          px0 = std::min(px0, p.x()), px1 = std::max(px1, p.x());
          py0 = std::min(py0, p.y()), py1 = std::max(py1, p.y());
        }
      }
      // Pixels are painted when their centre is covered, so edges agree within a pixel and a
      // half (a thin corner may miss every centre); the image clips the projection.
      auto clip = [](double v) { return std::clamp(v, 0.0, static_cast<double>(kSize)); };
      EXPECT_NEAR(x0, clip(px0), 1.5) << "seed " << seed << " move " << move;
      EXPECT_NEAR(x1 + 1, clip(px1), 1.5) << "seed " << seed << " move " << move;
      EXPECT_NEAR(y0, clip(py0), 1.5) << "seed " << seed << " move " << move;
      EXPECT_NEAR(y1 + 1, clip(py1), 1.5) << "seed " << seed << " move " << move;
      // And the gripper is well inside the picture, not a sliver at its edge.
      EXPECT_GT((x1 - x0) * (y1 - y0), 50);
    }
  }
}

TEST(KukaRenderTest, GripperStandsOutFromTheTrayInGrayscale) {
  // A DQN sees grayscale frames, so where the gripper covers the tray its luma must differ
  // clearly from the tray's, or the network cannot tell where the gripper is. Compare the 48 x 48
  // image with and without the gripper on the pixels the gripper covers, as it descends.
  KukaDiverseObjectEnv env;
  KukaRenderer renderer;
  constexpr int kSize = 48;
  for (uint64_t seed : {5, 6}) {
    env.Reset(seed);
    for (int step = 0; step < 5; ++step) {
      std::vector<DrawItem> all, without, gripper;
      env.scene().CollectDrawItems(&all);
      for (const DrawItem& d : all) {
        (d.group == DrawGroup::kGripper ? gripper : without).push_back(d);
      }
      std::vector<uint8_t> full, hidden, alone;
      renderer.Render(env.camera(), all, kSize, kSize, &full);
      renderer.Render(env.camera(), without, kSize, kSize, &hidden);
      renderer.Render(env.camera(), gripper, kSize, kSize, &alone);
      double sum = 0;
      int covered = 0;
      for (int i = 0; i < kSize * kSize; ++i) {
        if (IsWhite(alone, i) || IsWhite(hidden, i)) continue;
        sum += std::abs(PixelLuma(full, i) - PixelLuma(hidden, i));
        ++covered;
      }
      ASSERT_GT(covered, 5) << "seed " << seed << " step " << step;
      // About 8 levels of 255 on the earlier mid-grey tray; 41..73 on the dark one.
      EXPECT_GT(sum / covered, 30.0) << "seed " << seed << " step " << step;
      env.Step(rl::envs::DiscreteAction(0));  // stay: the gripper only descends
    }
  }
}

}  // namespace
}  // namespace rl::envs::kuka
