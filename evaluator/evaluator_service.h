// The evaluator's LCM service: it scores the checkpoints the learner announces and keeps the
// run's evaluation history (eval.jsonl) and report (report/) up to date.
//
// Channels:
//   in:  RL_CHECKPOINT (checkpoint_t)       a checkpoint file was written completely
//   out: RL_EVAL (eval_result_t)            one per scored checkpoint
//        RL_STATS_EVALUATOR (stats_evaluator_t), a few times per second
//
// An announced checkpoint is read only when it is a regular file of a bounded size directly in
// the run's checkpoint folder, <out_dir>/checkpoints (announced_checkpoint.h); any other path
// (a device, a FIFO, a symbolic link, a file elsewhere) is refused and counted, like a file that
// does not load. Without an out_dir every announcement is refused.
//
// Only the newest announced checkpoint that is not scored yet is kept: when the learner writes
// checkpoints faster than they are scored, the older unscored ones are skipped (and counted).
// Scoring runs in the thread that calls Poll(), between Bus::Handle() calls.
#pragma once

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <functional>
#include <limits>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "common/lcm_bus.h"
#include "evaluator/report.h"
#include "evaluator/scorer.h"
#include "nn/checkpoint.h"
#include "nn/sequential.h"
#include "rlmsg/checkpoint_t.hpp"

namespace rl::evaluator {

/// Settings of the evaluator service.
struct EvaluatorConfig {
  std::string env_id = "CartPole-v1";         // env the checkpoints are scored on
  int episodes = 100;                         // evaluation episodes per checkpoint
  double epsilon = kDefaultEvalEpsilon;       // exploration rate while scoring
  double gamma = kDefaultGamma;               // discount of the value estimates (the actors' gamma)
  uint64_t seed_base = kDefaultEvalSeedBase;  // episode i is reset with seed seed_base + i
  std::string out_dir;  // run folder: out_dir/eval.jsonl and out_dir/report/; empty: no files
  double goal = std::nan("");         // mean return that counts as solved; NaN: the env's threshold
  bool stop_at_goal = false;          // Run() returns once a checkpoint reaches the goal
  std::string run_config_text;        // shown in the report
  std::string run_name;               // shown in the report's title; empty: out_dir's folder name
  double stats_period_seconds = 0.3;  // stats_evaluator_t period (about 3 Hz)
  bool videos = false;    // record a greedy episode of every new best checkpoint (report/), and
                          // for pixel envs a grid of its camera frames
  int video_width = 360;  // video frame size in pixels
  int video_height = 240;
  double video_fps = 30;  // frames per second of the videos
  // Pixel envs: states of greedy episodes in report/tsne.png, the t-SNE map of the last hidden
  // layer of a new best checkpoint (tsne_map.h; when: kTsneTimeShare below); 0: no map.
  int tsne = 0;
  // A second metric beside the standard one: new best checkpoints are also scored on this env
  // (the same observations and actions; e.g. the rules a paper trained and tested with), over
  // second_episodes episodes from seed_base, and the report shows both. Empty: none.
  std::string second_env;
  int second_episodes = 100;
  std::string second_name;  // what the report calls it (default: the env id)

  /// Throws std::invalid_argument saying what is wrong.
  void Validate() const;
};

/// When the t-SNE map of a new best checkpoint (EvaluatorConfig::tsne) is made. Maps are made
/// after the checkpoint's result is published, and only while all maps, this one's expected
/// duration included, take at most kTsneTimeShare of the evaluator's time since it started; until
/// then the report keeps the last map and the newest best's map stays due (made between later
/// checkpoints when the share allows). A map's expected duration is the last one's, or
/// kTsneFirstGuessSeconds before the first. A checkpoint that reaches the goal, after which the run
/// usually ends, gets its map before its result is published when it is expected to take at most
/// kTsneGoalSeconds: that delays the end of the run by as much, once.
inline constexpr double kTsneTimeShare = 0.2;
inline constexpr double kTsneFirstGuessSeconds = 5.0;
inline constexpr double kTsneGoalSeconds = 15.0;

/// Loads a checkpoint file and builds its network; fills *meta when not null. Throws
/// std::runtime_error with the reason when the file is refused (see ScoreCheckpointFile).
nn::Sequential LoadPolicyNetwork(const std::string& path, const std::string& env_id,
                                 nn::CheckpointMeta* meta = nullptr);

/// The network of a loaded checkpoint (`path` names it in errors), checked against `env_id`.
/// Throws std::runtime_error as LoadPolicyNetwork.
nn::Sequential PolicyNetwork(const nn::Checkpoint& ckpt, const std::string& path,
                             const std::string& env_id);

/// ScoreCheckpointFile of a loaded checkpoint (`path` names it in the record and in errors).
EvalRecord ScoreCheckpoint(const nn::Checkpoint& ckpt, const std::string& path,
                           const std::string& env_id, int episodes, double epsilon,
                           uint64_t first_seed, double gamma = kDefaultGamma,
                           const std::function<void()>& after_episode = {});

/// Loads a checkpoint file, builds its network and scores it on `env_id` (see ScorePolicy), with
/// its value estimates against the returns (discount gamma).
/// The record's update, env_steps and wall_seconds come from the file's metadata. Throws
/// std::runtime_error with the reason when the file is refused: it does not load (missing,
/// truncated, corrupted, foreign), its architecture does not build, its parameters do not fit
/// the architecture, or the network does not fit the env. `after_episode` as in ScorePolicy.
EvalRecord ScoreCheckpointFile(const std::string& path, const std::string& env_id, int episodes,
                               double epsilon, uint64_t first_seed, double gamma = kDefaultGamma,
                               const std::function<void()>& after_episode = {});

/// The service. Not thread-safe: construct it, call Poll() or Run() and read it from one thread,
/// the thread that uses `bus`.
class EvaluatorService {
 public:
  /// Subscribes to RL_CHECKPOINT on `bus` (not owned; must outlive the service). With an
  /// out_dir, creates it, loads the history of an existing out_dir/eval.jsonl and writes the
  /// report. Progress lines go to `progress` (not owned; nullptr: none). Throws
  /// std::invalid_argument for a bad config or env and std::runtime_error when out_dir cannot
  /// be created.
  EvaluatorService(EvaluatorConfig config, Bus* bus, std::FILE* progress = stdout);
  EvaluatorService(const EvaluatorService&) = delete;
  EvaluatorService& operator=(const EvaluatorService&) = delete;
  /// The subscription stays on the bus (it cannot unsubscribe) but does nothing afterwards.
  ~EvaluatorService();

  /// Waits at most timeout_ms for announcements (less when stats are due), scores the pending
  /// checkpoint if there is one, and publishes stats when due. Returns true when stop_at_goal is
  /// set and the checkpoint just scored reached the goal.
  bool Poll(int timeout_ms);

  /// Polls until StopRequested() or, with stop_at_goal, until a checkpoint reaches the goal;
  /// then rewrites the report and publishes stats one last time.
  void Run();

  /// Scores the pending checkpoint, if any. Returns true when it reached the goal.
  bool ScorePending();

  /// Rewrites out_dir/report/ (no-op without out_dir). Logs, never throws.
  void WriteReportNow();
  /// Records report/best.webm, a greedy episode of the checkpoint `ckpt` (read from `path`), and
  /// for pixel envs report/frames.png, its grid of camera frames.
  void RecordVideo(const nn::Checkpoint& ckpt, const std::string& path, const EvalRecord& record);
  /// Whether a t-SNE map is due (a new best checkpoint not mapped yet, with config.tsne > 0).
  bool tsne_map_due() const { return tsne_net_.has_value(); }
  /// Seconds spent on t-SNE maps so far.
  double tsne_seconds() const { return tsne_seconds_; }

  /// Publishes stats_evaluator_t now.
  void PublishStats();

  /// "evaluator: goal reached" or "evaluator: goal not reached (best X)".
  std::string FinalLine() const;

  double goal() const { return goal_; }
  bool goal_reached() const { return goal_reached_; }
  bool has_pending() const { return pending_.has_value(); }
  /// Every record, resumed ones first, in scoring order.
  const std::vector<EvalRecord>& records() const { return records_; }
  int64_t checkpoints_scored() const { return scored_; }
  int64_t checkpoints_skipped() const { return skipped_; }
  int64_t checkpoints_refused() const { return refused_; }
  /// Announcements of checkpoints already scored (by file name and update), ignored.
  int64_t duplicates_ignored() const { return duplicates_; }
  /// Best record so far (including resumed ones), or nullptr.
  const EvalRecord* best() const;
  const std::string& eval_jsonl_path() const { return jsonl_path_; }
  const std::string& report_dir() const { return report_dir_; }

 private:
  void OnCheckpoint(const rlmsg::checkpoint_t& msg);
  // <out_dir>/checkpoints, the only folder announced checkpoints are read from (empty without
  // an out_dir: every announcement is refused).
  std::string CheckpointFolder() const;
  // Makes report/tsne.png for the due network now, with progress lines and stats; logs failures.
  // Returns true when the map was written. A stop request during it leaves the map due.
  bool MakeTsneMap();
  // MakeTsneMap() when a map is due and the time share allows it; rewrites the report after it.
  void MakeDueTsneMap();
  // The expected duration of the next map.
  double ExpectedTsneSeconds() const;
  void Log(const char* fmt, ...) const __attribute__((format(printf, 2, 3)));

  EvaluatorConfig config_;
  Bus* bus_;
  std::FILE* progress_;
  double goal_ = 0;
  std::string jsonl_path_;  // empty without out_dir
  std::string report_dir_;  // empty without out_dir
  std::string run_name_;
  std::string eval_settings_;

  std::optional<rlmsg::checkpoint_t> pending_;
  std::set<std::pair<std::string, int64_t>> scored_keys_;  // file name and update
  std::vector<EvalRecord> records_;
  int64_t scored_ = 0;
  int64_t skipped_ = 0;
  int64_t refused_ = 0;
  double best_video_mean_ = -std::numeric_limits<double>::infinity();
  double best_second_mean_ = -std::numeric_limits<double>::infinity();  // standard metric
  std::string video_caption_;   // empty until a video was recorded
  bool has_frames_ = false;     // a pixel env: the report gets a grid of camera frames
  std::string frames_caption_;  // empty until a frame grid was written
  // The t-SNE map: the network and record of the best checkpoint whose map is due.
  std::optional<nn::Sequential> tsne_net_;
  EvalRecord tsne_record_;
  double best_tsne_mean_ = -std::numeric_limits<double>::infinity();
  double tsne_seconds_ = 0;       // spent on maps, aborted ones included
  double last_tsne_seconds_ = 0;  // the last map written took this long (0: none yet)
  std::string tsne_caption_;      // empty until a map was written
  double start_time_ = 0;         // MonoSeconds() at construction
  int64_t duplicates_ = 0;
  double last_mean_ = 0;
  bool busy_ = false;
  bool goal_reached_ = false;
  double next_stats_time_ = 0;  // MonoSeconds() when stats are due
  // Points at this service while it lives; the bus handler holds a copy.
  std::shared_ptr<EvaluatorService*> alive_ = std::make_shared<EvaluatorService*>(this);
};

}  // namespace rl::evaluator
