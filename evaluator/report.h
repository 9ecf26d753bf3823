// The evaluator's outputs: eval.jsonl (one JSON line per scored checkpoint, appended and synced,
// so a restarted evaluator keeps the history) and report/ (index.html with the summary, two
// learning-curve SVGs, a table of every checkpoint and the run's config).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace rl::evaluator {

/// The score of one checkpoint.
struct EvalRecord {
  std::string checkpoint;   // file name of the checkpoint (no directory)
  int64_t update = 0;       // learner update count of the checkpoint
  int64_t env_steps = 0;    // transitions the replay had received at the checkpoint
  double wall_seconds = 0;  // seconds since the learner started, at the checkpoint
  double mean = 0;          // mean undiscounted return of the evaluation episodes
  double std = 0;           // population std of the returns
  double min = 0;
  double max = 0;
  int episodes = 0;         // evaluation episodes
  double eval_seconds = 0;  // seconds the scoring took
  // The network's value estimates against the returns that followed (ValueCalibration); all
  // zero and no correlation when not measured (value_steps 0).
  int64_t value_steps = 0;
  double value_estimate = 0;                // mean Q(s_t, a_t) of the actions taken
  double value_return = 0;                  // mean discounted return that followed them
  std::optional<double> value_correlation;  // unset when undefined (a constant series)
  // The checkpoint on the second metric (EvaluatorConfig::second_env), scored for new best
  // checkpoints only; second_episodes 0: not scored.
  int second_episodes = 0;
  double second_mean = 0;
  double second_std = 0;

  bool operator==(const EvalRecord&) const = default;
};

/// One line of eval.jsonl, without the newline: {"checkpoint": ..., "update": ..., "env_steps":
/// ..., "wall_seconds": ..., "mean": ..., "std": ..., "min": ..., "max": ..., "episodes": ...,
/// "eval_seconds": ...}, and when value_steps > 0 also "value_steps", "value_estimate",
/// "value_return" and "value_correlation" (null when unset), and when second_episodes > 0
/// "second_mean", "second_std" and "second_episodes". Numbers are written in their
/// shortest form that reads back exactly; a non-finite number is written as null.
std::string ToJson(const EvalRecord& record);

/// Parses one line written by ToJson (keys in any order, unknown keys ignored, whitespace
/// allowed). Returns false, leaving *record unspecified, when the line is not such an object or
/// lacks "checkpoint", "update" or "mean".
bool ParseJson(const std::string& line, EvalRecord* record);

/// Appends ToJson(record) and a newline to the file at `path` (created if missing), then
/// flushes and fsyncs it. Throws std::runtime_error naming the file on an I/O error.
void AppendJsonLine(const std::string& path, const EvalRecord& record);

/// Reads the records of an eval.jsonl. A missing file gives no records; a line that does not
/// parse (such as a line torn by a crash) is skipped and counted in *skipped_lines if given.
std::vector<EvalRecord> LoadJsonLines(const std::string& path, int* skipped_lines = nullptr);

/// What the report shows besides the records.
struct ReportInfo {
  std::string env_id;         // e.g. "CartPole-v1"
  std::string run_name;       // name of the run (its folder's name); may be empty
  int64_t run_id = 0;         // the run's id
  double goal = 0;            // mean return that counts as solved; dashed line in the curves
  std::string run_config;     // the run's config text, shown verbatim (escaped) in a <pre>
  std::string eval_settings;  // one line on how checkpoints were scored (episodes, epsilon, seeds)
  std::string second_name;    // what the records' second metric is (empty: none)
  int64_t checkpoints_skipped = 0;  // announced but superseded before scoring
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

/// Escapes &, <, >, " and ' for HTML text and attribute values.
std::string HtmlEscape(const std::string& text);

}  // namespace rl::evaluator
