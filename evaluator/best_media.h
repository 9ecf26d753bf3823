// The report's pictures of the best checkpoint so far: a greedy episode as a video
// (report/best.webm, video.h) and, for pixel envs, a grid of its camera frames
// (report/frames.png, frame_grid.h).
#pragma once

#include <cstdint>
#include <limits>
#include <string>

#include "evaluator/eval_history.h"
#include "evaluator/progress.h"
#include "evaluator/report.h"
#include "nn/checkpoint.h"

namespace rl::evaluator {

struct BestMediaConfig {
  std::string env_id;
  uint64_t seed_base = 0;  // the video's episode seed, and the first of the frame grid's
  int video_width = 360;   // pixels
  int video_height = 240;
  double video_fps = 30;
  std::string report_dir;  // where the files go
  // The best standard-metric mean of the evaluator's earlier life in this run folder (its
  // resumed history): only a checkpoint above it is a new best, and
  // until then the report shows the media that life recorded.
  double best_before = -std::numeric_limits<double>::infinity();
};

/// Records the media of every new best checkpoint. Not thread-safe.
class BestMedia {
 public:
  /// Throws std::invalid_argument for an unknown env id. With a best_before, the captions of the
  /// media already in report_dir are read (ReadCaption).
  explicit BestMedia(BestMediaConfig config);

  /// When `record` is better than the best recorded so far, records the video of the checkpoint
  /// `ckpt` (read from `path`) and, for a pixel env, its frame grid. Failures are logged (stderr);
  /// a checkpoint whose video failed stays a candidate for the next one. `tick` as in progress.h:
  /// what it throws (Interrupted) propagates, and the media are then left as they were.
  void RecordIfBest(const nn::Checkpoint& ckpt, const std::string& path, const EvalRecord& record,
                    const Tick& tick = {});

  /// Names the written files and their captions in `info`.
  void AddTo(ReportInfo* info) const;

 private:
  std::string Path(const char* file) const;  // of a file in report_dir

  BestMediaConfig config_;
  bool has_frames_ = false;  // a pixel env: a frame grid too
  double best_mean_;
  std::string video_caption_;   // empty until a video was recorded
  std::string frames_caption_;  // empty until a frame grid was written
};

}  // namespace rl::evaluator
