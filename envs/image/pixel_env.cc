#include "envs/image/pixel_env.h"

#include <cstdint>
#include <stdexcept>
#include <string>
#include <utility>

#include <opencv2/core/utility.hpp>

#include "envs/image/action_repeat.h"
#include "envs/image/clip_reward.h"
#include "envs/image/frame_processor.h"
#include "envs/image/frame_stack.h"

namespace rl::envs {

std::unique_ptr<Env> MakePixelEnv(std::unique_ptr<Env> inner, const ImagePipelineConfig& config) {
  if (inner == nullptr) throw std::invalid_argument("MakePixelEnv: the inner env must not be null");
  config.Validate();
  // Our processes step one env per thread; OpenCV's own worker threads would only compete with
  // the other processes of the run for the cores (several actors, the learner).
  cv::setNumThreads(1);
  // inner -> action repeat + max-pool -> grayscale, crop, resize -> stack -> reward clip.
  auto frames = std::make_unique<ActionRepeat>(std::move(inner), config);
  auto processed = std::make_unique<FrameProcessor>(std::move(frames), config);
  std::unique_ptr<Env> env = std::make_unique<FrameStack>(std::move(processed), config);
  if (config.clip_rewards) env = std::make_unique<ClipReward>(std::move(env));
  return env;
}

}  // namespace rl::envs
