// Off-screen rendering of the KUKA scene with OSMesa (Mesa's software OpenGL, llvmpipe), legacy
// fixed-function OpenGL: flat-shaded meshes under one directional light, white background, like
// PyBullet's TinyRenderer in the reference (spec 4.9; pixel-exact agreement is not a goal).
//
// llvmpipe threads: unless LP_NUM_THREADS is already set, the first KukaRenderer in a process
// sets it to 1 (setenv, before the first OSMesa context exists, which is when llvmpipe reads it),
// so that each actor renders on its own thread only. setenv is not thread-safe: create the first
// renderer before starting threads that read the environment.
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "envs/kuka/kuka_camera.h"
#include "envs/kuka/kuka_geometry.h"

namespace rl::envs::kuka {

/// One OSMesa context and its colour and depth buffers. The GL functions come from
/// OSMesaGetProcAddress, so a libGL loaded by something else in the process cannot intercept
/// them. Not copyable; use from one thread at a time (each Render makes the context current on
/// the calling thread).
class KukaRenderer {
 public:
  /// Creates the context. Throws std::runtime_error if OSMesa cannot create it.
  KukaRenderer();
  ~KukaRenderer();
  KukaRenderer(const KukaRenderer&) = delete;
  KukaRenderer& operator=(const KukaRenderer&) = delete;

  /// Draws `items` as `camera` sees them into a width x height image (both in [1, 4096], else
  /// std::invalid_argument): *rgb becomes height x width x 3 bytes, row-major, top row first.
  void Render(const CameraParams& camera, std::span<const DrawItem> items, int width, int height,
              std::vector<uint8_t>* rgb);

 private:
  struct Gl;  // The OSMesa context and the GL entry points (kuka_renderer.cc).
  std::unique_ptr<Gl> gl_;
  std::vector<uint8_t> rgba_;  // The colour buffer OSMesa draws into (bottom row first).
};

}  // namespace rl::envs::kuka
