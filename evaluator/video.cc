#include "evaluator/video.h"

#include <cstdio>
#include <filesystem>
#include <stdexcept>
#include <system_error>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include "common/atomic_file.h"
#include "envs/registry.h"
#include "evaluator/scorer.h"

namespace rl::evaluator {

std::string VideoTemporaryPath(const std::string& path) { return path + ".tmp.webm"; }

VideoResult RecordGreedyVideo(nn::Sequential* net, const std::string& env_id, uint64_t seed,
                              int width, int height, double fps, const std::string& path,
                              const Tick& tick) {
  auto env = envs::MakeEnv(env_id);
  // The greedy policy (epsilon 0; no noise): throws when the network does not fit the env.
  const std::unique_ptr<actor::Policy> policy = EvaluationPolicy(*net, env->spec(), 0.0, seed);
  std::vector<float> action(static_cast<size_t>(env->spec().action_width()));
  // The encoder wants even frame sizes.
  width += width % 2;
  height += height % 2;
  const std::string tmp = VideoTemporaryPath(path);
  cv::VideoWriter writer(tmp, cv::CAP_FFMPEG, cv::VideoWriter::fourcc('V', 'P', '8', '0'), fps,
                         cv::Size(width, height));
  if (!writer.isOpened()) {
    throw std::runtime_error("cannot open a WebM (VP8) encoder for " + tmp +
                             " (OpenCV built without FFmpeg?)");
  }
  VideoResult result;
  result.width = width;
  result.height = height;
  std::vector<uint8_t> rgb;
  cv::Mat bgr(height, width, CV_8UC3);
  auto write_frame = [&] {
    env->RenderSized(width, height, &rgb);
    const cv::Mat frame(height, width, CV_8UC3, rgb.data());
    cv::cvtColor(frame, bgr, cv::COLOR_RGB2BGR);
    writer.write(bgr);
    ++result.frames;
  };
  try {
    env->Reset(seed);
    write_frame();
    while (true) {
      const auto obs = env->observation();
      policy->Act(obs, 0, action);
      const envs::StepResult r = env->Step(action);
      result.episode_return += r.reward;
      write_frame();
      if (tick) tick();
      if (r.terminated || r.truncated) break;
    }
  } catch (...) {
    // Interrupted by the tick, or failed: no half-written temporary left behind.
    writer.release();
    std::error_code ignored;
    std::filesystem::remove(tmp, ignored);
    throw;
  }
  writer.release();
  RenameIntoPlace(tmp, path, "video");
  return result;
}

}  // namespace rl::evaluator
