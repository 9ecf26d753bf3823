// The options of the image pipeline (pixel_env.h), apart from the pipeline itself so that the
// spec of a pixel env can be computed without OpenCV (envs/specs.h).
#pragma once

namespace rl::envs {

/// Largest frame side (render and output sizes, pixels) and stack: those of the largest frames
/// the messages carry (common/messages.cc), so that a frame and a stack fit an int.
inline constexpr int kMaxFrameSide = 4096;
inline constexpr int kMaxFrameStack = 64;

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
  // Inner steps with the zero action after every Reset, their rewards discarded (the TD3
  // CarRacing article plays 45 while the camera zooms in). An episode that ends during them is
  // reset again.
  int noop_start = 0;
  // Inner steps after which an episode is truncated, replacing the env's own time limit
  // (EnvSpec::max_episode_steps); 0 keeps it. The TD3 CarRacing article tests for 18,000.
  int time_limit = 0;

  /// Throws std::invalid_argument naming the field unless: render_width and render_height are
  /// both 0 or both positive, frame_skip >= 1, the crops are >= 0 (and, with an explicit render
  /// size, leave at least one pixel each way), width and height are both 0 or both positive,
  /// stack >= 1, noop_start >= 0 and time_limit >= 0; and the sizes are at most kMaxFrameSide, the
  /// stack at most kMaxFrameStack.
  void Validate() const;
};

}  // namespace rl::envs
