#include "evaluator/best_media.h"

#include <cmath>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <utility>

#include "common/text_format.h"
#include "envs/specs.h"
#include "evaluator/checkpoint_file.h"
#include "evaluator/frame_grid.h"
#include "evaluator/progress.h"
#include "evaluator/video.h"

namespace rl::evaluator {

BestMedia::BestMedia(BestMediaConfig config)
    : config_(std::move(config)), best_mean_(config_.best_before) {
  has_frames_ = envs::LookupSpec(config_.env_id).frame_height > 0;
  if (std::isfinite(config_.best_before) && !config_.report_dir.empty()) {
    video_caption_ = ReadCaption(Path(kBestVideo));
    if (has_frames_) frames_caption_ = ReadCaption(Path(kFrameGrid));
  }
}

std::string BestMedia::Path(const char* file) const {
  return (std::filesystem::path(config_.report_dir) / file).string();
}

void BestMedia::RecordIfBest(const nn::Checkpoint& ckpt, const std::string& path,
                             const EvalRecord& record, const Tick& tick) {
  if (!(record.mean > best_mean_)) return;
  // One network serves the video and the frame grid.
  nn::Sequential net;
  try {
    net = PolicyNetwork(ckpt, path, config_.env_id);
  } catch (const std::exception& e) {
    LogError(std::string("no video: ") + e.what());
    return;
  }
  const auto seed = static_cast<unsigned long long>(config_.seed_base);
  try {
    const VideoResult v =
        RecordGreedyVideo(&net, config_.env_id, config_.seed_base, config_.video_width,
                          config_.video_height, config_.video_fps, Path(kBestVideo), tick);
    best_mean_ = record.mean;
    char caption[256];
    std::snprintf(caption, sizeof(caption),
                  "Greedy episode (epsilon 0, seed %llu) of the best checkpoint, %s (update %lld, "
                  "evaluation mean %s): return %s over %d frames.",
                  seed, record.checkpoint.c_str(), static_cast<long long>(record.update),
                  rl::Score(record.mean).c_str(), rl::Score(v.episode_return).c_str(), v.frames);
    video_caption_ = caption;
    WriteCaption(Path(kBestVideo), video_caption_);
  } catch (const std::exception& e) {
    LogError(std::string("no video: ") + e.what());
  }
  if (!has_frames_) return;
  try {
    const FrameGridResult g =
        WriteFrameGrid(&net, config_.env_id, config_.seed_base, kFrameGridEpisodes,
                       kFrameGridColumns, Path(kFrameGrid), tick);
    char caption[384];
    std::snprintf(caption, sizeof(caption),
                  "%d greedy episodes (epsilon 0, seeds %llu to %llu) of %s (update %lld), one row "
                  "each: the camera image as rendered (left) and the frame the network receives "
                  "(right) after reset and after every step; mean return %.2f.",
                  g.episodes, seed, seed + static_cast<unsigned long long>(g.episodes) - 1,
                  record.checkpoint.c_str(), static_cast<long long>(record.update), g.mean_return);
    frames_caption_ = caption;
    WriteCaption(Path(kFrameGrid), frames_caption_);
  } catch (const std::exception& e) {
    LogError(std::string("no frame grid: ") + e.what());
  }
}

void BestMedia::AddTo(ReportInfo* info) const {
  if (!video_caption_.empty()) {
    info->video_file = kBestVideo;
    info->video_caption = video_caption_;
  }
  if (!frames_caption_.empty()) {
    info->frames_file = kFrameGrid;
    info->frames_caption = frames_caption_;
  }
}

}  // namespace rl::evaluator
