// The image pipeline that turns any discrete env with a Render() into a pixel env for a
// convolutional DQN, in the spirit of the Atari preprocessing of Mnih et al. (2015) and
// Gymnasium's AtariPreprocessing and FrameStackObservation wrappers:
//
//   inner -> ActionRepeat (action repeat + max-pool, RGB) -> FrameProcessor (grayscale, crop,
//   area resize) -> FrameStack (stack, observation in [0, 1]) -> ClipReward (optional)
//
// MakePixelEnv builds the whole chain; each wrapper also works alone (see their headers).
#pragma once

#include <memory>

#include "envs/env.h"

namespace rl::envs {

/// Options of the image pipeline. Every wrapper takes the whole struct and reads its own fields.
struct ImagePipelineConfig {
  // Raw frames come from inner->RenderSized(render_width, render_height), or from inner->Render()
  // at the native size when both are 0.
  int render_width = 0;
  int render_height = 0;
  // Action repeat k >= 1: each Step applies the action k times and sums the rewards, stopping
  // early on terminated or truncated.
  int frame_skip = 1;
  // The frame of a Step is the pixelwise max of the raw frames after its last two inner steps
  // (after one inner step: that frame; after Reset: the reset frame). Off: the last raw frame.
  bool max_pool = true;
  // Pixels removed from each side of the raw frame, before resizing.
  int crop_top = 0;
  int crop_bottom = 0;
  int crop_left = 0;
  int crop_right = 0;
  // Output frame size, resized from the cropped frame with area interpolation (cv::INTER_AREA);
  // both 0 keep the cropped size.
  int width = 84;
  int height = 84;
  // Frames in the observation (EnvSpec::frame_stack), oldest first.
  int stack = 4;
  // Clamp each Step's (summed) reward to [-1, 1].
  bool clip_rewards = false;

  /// Throws std::invalid_argument naming the field unless: render_width and render_height are
  /// both 0 or both positive, frame_skip >= 1, the crops are >= 0 (and, with an explicit render
  /// size, leave at least one pixel each way), width and height are both 0 or both positive, and
  /// stack >= 1.
  void Validate() const;
};

/// Wraps `inner` in the pipeline above and returns a pixel env. Its spec has the inner env's id,
/// num_actions and reward_threshold, max_episode_steps = ceil(inner's / frame_skip),
/// frame_height x frame_width = the output size (the cropped size when width and height are 0),
/// frame_stack = stack and observation_size = stack * frame_height * frame_width. observation()
/// is the stacked frames, oldest first, each byte / 255.0f; frame() is the newest frame's bytes;
/// after any Reset the stack holds the first frame `stack` times. Render() and RenderSized()
/// forward to the inner env (full-quality video).
///
/// Step and Reset reuse buffers sized at construction, so they do not allocate after the first
/// Reset, provided the inner env's do not: Catch's Step, Reset() and rendering do not, but any
/// seeded Reset(seed) allocates in std::seed_seq (SeedRng, envs/rng.cc), CartPole's rendering
/// allocates a small vector per polygon, and the default Env::RenderSized a whole native image.
/// One exception inside OpenCV: cv::resize with INTER_AREA mallocs a small table on every call
/// when the size ratio is not an integer; an integer ratio (e.g. render 168x168 for an 84x84
/// output) avoids it.
///
/// With render_width and render_height 0 the raw size is learnt at construction by resetting the
/// inner env once with seed 0 and rendering it, so a later unseeded Reset() of the inner env
/// continues that stream instead of drawing a random seed; pass a render size to avoid this.
///
/// Sets OpenCV to one thread (cv::setNumThreads(1)) for the whole process: each of our processes
/// steps its envs on one thread, and OpenCV's workers would compete with the run's other
/// processes for the cores.
///
/// Throws std::invalid_argument if inner is null, is a continuous env (num_actions == 0; DQN is
/// discrete), config.Validate() fails, or the crop leaves no pixel of the raw frame.
std::unique_ptr<Env> MakePixelEnv(std::unique_ptr<Env> inner, const ImagePipelineConfig& config);

}  // namespace rl::envs
