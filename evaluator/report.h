// The run's report: report/index.html with the summary, the learning and training curves, the
// evaluator's media, a table of every checkpoint, the restarts and the run's config, written from
// the evaluation history (eval_history.h) and what the run folder holds. No physics, rendering or
// OpenCV: the compare page (tools/compare_runs.h) links it too.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "evaluator/eval_history.h"
#include "evaluator/svg_canvas.h"

namespace rl::evaluator {

/// Escapes &, <, >, " and ' for HTML text and attribute values.
using plot::HtmlEscape;

/// What the report shows besides the records.
struct ReportInfo {
  std::string env_id;         // e.g. "CartPole-v1"
  std::string run_name;       // name of the run (its folder's name); may be empty
  int64_t run_id = 0;         // the run's id
  double goal = 0;            // mean return that counts as solved; dashed line in the curves
  std::string run_config;     // the run's config text, shown verbatim (escaped) in a <pre>
  std::string eval_settings;  // one line on how checkpoints were scored (episodes, epsilon, seeds)
  std::string second_name;    // what the records' second metric is (empty: none)
  int64_t checkpoints_skipped = 0;  // superseded before scoring and dropped unscored
  int64_t checkpoints_refused = 0;  // files that failed to load or did not fit the env
  std::string video_file;           // a video in the report folder to show (empty: none)
  std::string video_caption;        // what the video shows
  std::string frames_file;          // a grid of camera frames (PNG) in the report folder, or empty
  std::string frames_caption;       // what the grid shows
  std::string tsne_file;            // a t-SNE map (PNG) in the report folder, or empty
  std::string tsne_caption;         // what the map shows
  // The run's metrics.jsonl (tools/metrics_log.h), drawn as training curves; empty or missing:
  // no training section.
  std::string metrics_file;
  // The launch script's restarts file (lines "<time> <role> status <code> restart <n>"), shown as
  // a table of the run's process restarts; empty or missing: none shown.
  std::string restarts_file;
};

/// Names of the files WriteReport writes into `dir`.
inline constexpr char kReportIndex[] = "index.html";
inline constexpr char kCurveEnvSteps[] = "curve_env_steps.svg";
inline constexpr char kCurveWallTime[] = "curve_wall_time.svg";
inline constexpr char kBestVideo[] = "best.webm";
inline constexpr char kFrameGrid[] = "frames.png";
inline constexpr char kTsneMap[] = "tsne.png";
/// A media file's caption lives beside it (<media_path>.caption), so that an evaluator resumed in
/// the same run folder still shows the media of its earlier life's best checkpoint.
/// WriteCaption, called once the media file is written, writes it atomically with the file's
/// size and modification time; ReadCaption returns it only while those still match, else ""
/// (no media file, no caption, or a media file rewritten since: a crash between the two
/// writes leaves a new file under no caption rather than under the old one).
void WriteCaption(const std::string& media_path, const std::string& caption);
std::string ReadCaption(const std::string& media_path);

/// Greedy episodes (rows) and cells per row of the frame grid of a pixel env's report.
inline constexpr int kFrameGridEpisodes = 4;
inline constexpr int kFrameGridColumns = 8;

/// Writes dir/index.html, dir/curve_env_steps.svg and dir/curve_wall_time.svg (creating dir if
/// needed). Each file is written to a temporary file in dir, synced and renamed over the old
/// one, so a reader never sees a partial file. The HTML is self-contained (no scripts, no
/// network fetches): a title with the env and run, a summary (best mean and where it was
/// reached, whether the goal was reached), the two learning curves, a table of all checkpoints
/// (newest first) and the run's config. Throws std::runtime_error naming the file on an I/O
/// error.
void WriteReport(const std::string& dir, const std::vector<EvalRecord>& records,
                 const ReportInfo& info);

}  // namespace rl::evaluator
