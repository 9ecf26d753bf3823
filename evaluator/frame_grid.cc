#include "evaluator/frame_grid.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "common/atomic_file.h"
#include "envs/registry.h"
#include "evaluator/report.h"
#include "evaluator/scorer.h"

namespace rl::evaluator {
namespace {

// Nearest-neighbour scaling to `height` rows, keeping the aspect ratio: every source pixel stays a
// visible block.
cv::Mat ScaledToHeight(const cv::Mat& image, int height) {
  const int width =
      std::max(1, static_cast<int>(std::lround(static_cast<double>(image.cols) * height /
                                               static_cast<double>(image.rows))));
  cv::Mat out;
  cv::resize(image, out, cv::Size(width, height), 0, 0, cv::INTER_NEAREST);
  return out;
}

// The camera image beside the network's input frame, under `label`.
cv::Mat MakeCell(const envs::Env& env, const std::string& label) {
  std::vector<uint8_t> rgb;
  int w = 0, h = 0;
  env.Render(&rgb, &w, &h);
  cv::Mat camera;
  cv::cvtColor(cv::Mat(h, w, CV_8UC3, rgb.data()), camera, cv::COLOR_RGB2BGR);

  const envs::EnvSpec& spec = env.spec();
  const std::span<const uint8_t> frame = env.frame();
  if (frame.size() != static_cast<size_t>(spec.frame_height) * spec.frame_width) {
    throw std::logic_error("frame of " + std::to_string(frame.size()) + " bytes, spec says " +
                           std::to_string(spec.frame_height) + " x " +
                           std::to_string(spec.frame_width));
  }
  cv::Mat input;
  cv::cvtColor(
      cv::Mat(spec.frame_height, spec.frame_width, CV_8UC1, const_cast<uint8_t*>(frame.data())),
      input, cv::COLOR_GRAY2BGR);

  const cv::Mat left = ScaledToHeight(camera, kFrameGridImageHeight);
  const cv::Mat right = ScaledToHeight(input, kFrameGridImageHeight);
  cv::Mat cell(kFrameGridLabelHeight + kFrameGridImageHeight,
               left.cols + kFrameGridGap + right.cols, CV_8UC3, cv::Scalar(255, 255, 255));
  left.copyTo(cell(cv::Rect(0, kFrameGridLabelHeight, left.cols, left.rows)));
  right.copyTo(
      cell(cv::Rect(left.cols + kFrameGridGap, kFrameGridLabelHeight, right.cols, right.rows)));
  cv::putText(cell, label, cv::Point(2, kFrameGridLabelHeight - 4), cv::FONT_HERSHEY_PLAIN, 0.9,
              cv::Scalar(40, 40, 40), 1, cv::LINE_AA);
  return cell;
}

}  // namespace

FrameGridResult WriteFrameGrid(nn::Sequential* net, const std::string& env_id, uint64_t seed,
                               int episodes, int max_columns, const std::string& path,
                               const Tick& tick) {
  if (episodes < 1 || max_columns < 2) {
    throw std::invalid_argument("a frame grid needs at least 1 episode and 2 columns");
  }
  auto env = envs::MakeEnv(env_id);
  if (env->spec().frame_height <= 0) {
    throw std::invalid_argument(env_id + " has no camera frames (not a pixel env)");
  }
  // The greedy policy (epsilon 0; no noise): throws when the network does not fit the env.
  const std::unique_ptr<actor::Policy> policy = EvaluationPolicy(*net, env->spec(), 0.0, seed);
  std::vector<float> action(static_cast<size_t>(env->spec().action_width()));

  FrameGridResult result;
  std::vector<std::vector<cv::Mat>> rows;
  double total_return = 0;
  for (int e = 0; e < episodes; ++e) {
    env->Reset(seed + static_cast<uint64_t>(e));
    std::vector<cv::Mat> row{MakeCell(*env, "reset")};
    double episode_return = 0;
    for (int t = 1;; ++t) {
      const auto obs = env->observation();
      policy->Act(obs, 0, action);
      const envs::StepResult r = env->Step(action);
      episode_return += r.reward;
      const bool done = r.terminated || r.truncated;
      char label[64];
      if (done) {
        std::snprintf(label, sizeof(label), "step %d, return %g", t, episode_return);
      } else {
        std::snprintf(label, sizeof(label), "step %d", t);
      }
      // The first max_columns - 1 cells stay; the last column holds the newest cell.
      if (static_cast<int>(row.size()) < max_columns) {
        row.push_back(MakeCell(*env, label));
      } else if (done) {
        row.back() = MakeCell(*env, label);
      }
      if (tick) tick();
      if (done) break;
    }
    total_return += episode_return;
    result.columns = std::max(result.columns, static_cast<int>(row.size()));
    rows.push_back(std::move(row));
  }

  // Lay the rows out on a white page.
  const int row_height = kFrameGridLabelHeight + kFrameGridImageHeight;
  int width = 0;
  for (const auto& row : rows) {
    int w = kFrameGridGap;
    for (const cv::Mat& cell : row) w += cell.cols + kFrameGridGap;
    width = std::max(width, w);
  }
  const int height = kFrameGridGap + static_cast<int>(rows.size()) * (row_height + kFrameGridGap);
  cv::Mat page(height, width, CV_8UC3, cv::Scalar(255, 255, 255));
  for (size_t r = 0; r < rows.size(); ++r) {
    int x = kFrameGridGap;
    const int y = kFrameGridGap + static_cast<int>(r) * (row_height + kFrameGridGap);
    for (const cv::Mat& cell : rows[r]) {
      cell.copyTo(page(cv::Rect(x, y, cell.cols, cell.rows)));
      x += cell.cols + kFrameGridGap;
    }
  }
  std::vector<uchar> png;
  if (!cv::imencode(".png", page, png)) throw std::runtime_error("cannot encode " + path);
  WriteFileAtomically(path, std::string(png.begin(), png.end()));

  result.episodes = episodes;
  result.mean_return = total_return / episodes;
  result.width = width;
  result.height = height;
  return result;
}

}  // namespace rl::evaluator
