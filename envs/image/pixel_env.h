// The image pipeline that turns any env with a Render() (discrete or continuous) into a pixel env
// for a convolutional DQN, in the spirit of the Atari preprocessing of Mnih et al. (2015) and
// Gymnasium's AtariPreprocessing and FrameStackObservation wrappers:
//
//   inner -> ActionRepeat (action repeat + max-pool, RGB) -> FrameProcessor (grayscale, crop,
//   area resize) -> FrameStack (stack, observation in [0, 1]) -> ClipReward (optional)
//
// MakePixelEnv builds the whole chain; each wrapper also works alone (see their headers).
#pragma once

#include <memory>

#include "envs/env.h"
#include "envs/image/image_config.h"

namespace rl::envs {

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
/// Throws std::invalid_argument if inner is null, config.Validate() fails, or the crop leaves no
/// pixel of the raw frame.
std::unique_ptr<Env> MakePixelEnv(std::unique_ptr<Env> inner, const ImagePipelineConfig& config);

}  // namespace rl::envs
