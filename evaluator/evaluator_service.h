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
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "common/lcm_bus.h"
#include "evaluator/best_media.h"
#include "evaluator/checkpoint_file.h"
#include "evaluator/checkpoint_queue.h"
#include "evaluator/eval_history.h"
#include "evaluator/progress.h"
#include "evaluator/report.h"
#include "evaluator/scorer.h"
#include "evaluator/second_metric.h"
#include "evaluator/tsne_scheduler.h"
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
  // layer of a new best checkpoint (tsne_map.h; when: tsne_scheduler.h); 0: no map.
  int tsne = 0;
  // A second metric beside the standard one: new best checkpoints are also scored on this env
  // (the same observations and actions; e.g. the rules a paper trained and tested with), over
  // second_episodes episodes from seed_base, and the report shows both. Empty: none.
  std::string second_env;
  int second_episodes = 100;
  std::string second_name;  // what the report calls it (default: the env id)
  // Only a new best whose standard mean is at least this is scored on the second metric (its
  // episodes can be long, and the early bests of a run are not results anyone reports).
  double second_min_mean = -std::numeric_limits<double>::infinity();
  // The screen: before its full evaluation, a checkpoint plays the evaluation's first
  // screen_episodes episodes (the same seeds, so nothing unseen is spent), and earns the full
  // evaluation only when their mean is at least the best full evaluation's mean less
  // screen_margin. A checkpoint that fails is not scored: no eval.jsonl line, no RL_EVAL, only a
  // progress line and a count. The first checkpoint, and the next after screen_max_rejects
  // failures in a row (so that the curve keeps going), are evaluated in full unscreened.
  // screen_episodes 0: no screen, every checkpoint is evaluated in full.
  int screen_episodes = 0;
  double screen_margin = 0;
  int screen_max_rejects = 3;
  // After its own score, a checkpoint is also scored as an ensemble of it and the ensemble - 1
  // checkpoints before it in the run's checkpoint folder, on the same episodes (eval.jsonl's
  // ensemble_* fields, a second curve in the report); only when its own mean is at least
  // ensemble_min_mean and those checkpoints are there. 1: no ensembles. ensemble_by "actions"
  // (continuous envs): their mean action; "weights" (any env): the one network whose weights
  // are the mean of theirs (AverageCheckpoints), scored as a checkpoint is, the best such
  // network kept as <out_dir>/kBestAverageFile, a checkpoint file like the learner's.
  int ensemble = 1;
  std::string ensemble_by = "actions";
  double ensemble_min_mean = -std::numeric_limits<double>::infinity();
  // Checkpoints superseded by a newer one before their turn (scoring is slower than the
  // learner, or busy with a second metric, a video or a map) wait, up to this many, and are
  // scored later, newest first, when nothing newer waits; the learner may delete some meanwhile
  // (keep-checkpoints), and those, like the ones over the limit, are skipped. 0: every
  // superseded checkpoint is skipped.
  int backlog = 16;

  /// Throws std::invalid_argument saying what is wrong.
  void Validate() const;
};

/// The service. Not thread-safe: construct it, call Poll() or Run() and read it from one thread,
/// the thread that uses `bus`. It is made of small pieces: the announcements wait in a
/// CheckpointQueue, an announced file is read once (ReadAnnouncedCheckpoint) and scored by
/// ScoreCheckpoint (checkpoint_file.h), new best checkpoints get their SecondMetric, BestMedia
/// (video and frame grid) and t-SNE map (TsneScheduler) from the same read, and the history and
/// report are the report library's (EvalHistory, WriteReport).
class EvaluatorService {
 public:
  /// Subscribes to RL_CHECKPOINT on `bus` (not owned; must outlive the service). With an
  /// out_dir, creates it, loads the history of an existing out_dir/eval.jsonl, queues the
  /// checkpoints of out_dir/checkpoints that it does not hold (an earlier life's last
  /// announcements and backlog, lost with it) as if announced, and writes the report. Progress
  /// lines go to `progress` (not owned; nullptr: none). Throws std::invalid_argument for a bad
  /// config or env and std::runtime_error when out_dir cannot be created.
  EvaluatorService(EvaluatorConfig config, Bus* bus, std::FILE* progress = stdout);
  EvaluatorService(const EvaluatorService&) = delete;
  EvaluatorService& operator=(const EvaluatorService&) = delete;
  /// The subscription stays on the bus (it cannot unsubscribe) but does nothing afterwards.
  ~EvaluatorService();

  /// Waits at most timeout_ms for announcements (less when stats are due), scores the pending
  /// checkpoint if there is one (else, when no t-SNE map is due either, the newest one of the
  /// backlog), and publishes stats when due. Returns true when stop_at_goal is set and the
  /// checkpoint just scored reached the goal.
  bool Poll(int timeout_ms);

  /// Polls until StopRequested() or, with stop_at_goal, until a checkpoint reaches the goal;
  /// then rewrites the report and publishes stats one last time.
  void Run();

  /// Scores the pending checkpoint, if any. Returns true when it reached the goal.
  bool ScorePending();
  /// Scores the newest checkpoint of the backlog that is still there, if any. Returns true when
  /// it reached the goal.
  bool ScoreFromBacklog();

  /// Rewrites out_dir/report/ (no-op without out_dir). Logs, never throws.
  void WriteReportNow();
  /// Whether a t-SNE map is due (a new best checkpoint not mapped yet, with config.tsne > 0).
  bool tsne_map_due() const { return tsne_.due(); }
  /// Seconds spent on t-SNE maps so far.
  double tsne_seconds() const { return tsne_.seconds(); }

  /// Publishes stats_evaluator_t now.
  void PublishStats();

  /// "evaluator: goal reached" or "evaluator: goal not reached (best X)".
  std::string FinalLine() const;

  double goal() const { return report_.goal; }
  /// Whether some record (resumed ones included) reached the goal.
  bool goal_reached() const;
  bool has_pending() const { return queue_.has_pending(); }
  /// Superseded checkpoints waiting to be scored (EvaluatorConfig::backlog).
  int backlog() const { return queue_.backlog(); }
  /// Every record, resumed ones first, in scoring order.
  const std::vector<EvalRecord>& records() const { return history_.records(); }
  int64_t checkpoints_scored() const { return scored_; }
  /// Superseded checkpoints dropped unscored (EvaluatorConfig::backlog).
  int64_t checkpoints_skipped() const { return queue_.skipped(); }
  int64_t checkpoints_refused() const { return refused_; }
  /// Checkpoints that failed the screen (EvaluatorConfig::screen_episodes) and were not scored.
  int64_t checkpoints_screened_out() const { return screened_out_; }
  /// Announcements of checkpoints already scored (by file name and update), ignored.
  int64_t duplicates_ignored() const { return queue_.duplicates(); }
  /// Best record so far (including resumed ones), or nullptr.
  const EvalRecord* best() const { return history_.best(); }
  const std::string& eval_jsonl_path() const { return history_.path(); }
  const std::string& report_dir() const { return report_dir_; }

 private:
  // Reads the announced checkpoint (from the run's checkpoint folder only) into *ckpt and scores
  // it (with its second metric when a new best); nullopt when it was refused or a stop was
  // requested.
  std::optional<EvalRecord> Score(const rlmsg::checkpoint_t& announced, nn::Checkpoint* ckpt);
  // Scores the announced checkpoint and records, reports and announces the result (with its
  // video and map when a new best). Returns true when it reached the goal.
  bool ScoreAnnounced(const rlmsg::checkpoint_t& announced);
  // With config.ensemble > 1 and the record's mean at ensemble_min_mean or more, scores the
  // ensemble of the checkpoint `ckpt` (read from `path`) and the ones before it into the
  // record's ensemble_* fields (an average of weights: and keeps it when it is the best average
  // so far) and prints a progress line. Too few checkpoints before it, a file
  // that does not load or is of another run, and a stop request leave the record as it is; the
  // first two are logged. Throws Interrupted only through `tick` (caught here).
  void ScoreEnsembleIfDue(const nn::Checkpoint& ckpt, const std::string& path, EvalRecord* record);
  // Writes `average` (scored `mean`) to <out_dir>/kBestAverageFile, atomically, when no average
  // of the history scored as much; a failure to write is logged, nothing else.
  void KeepAverageIfBest(const nn::Checkpoint& average, double mean);
  // Whether the checkpoint earns its full evaluation: true without a screen (screen_episodes 0,
  // no best yet, or screen_max_rejects failures in a row), else whether the mean of its first
  // screen_episodes episodes reaches the best full mean less screen_margin. A failure is counted
  // and printed. Throws as ScoreCheckpoint.
  bool PassesScreen(const nn::Checkpoint& ckpt, const rlmsg::checkpoint_t& announced);
  // Publishes the result of `record` on RL_EVAL and prints its progress line.
  void Announce(const rlmsg::checkpoint_t& announced, const EvalRecord& record, bool reached);
  // <out_dir>/checkpoints, the only folder announced checkpoints are read from (empty without
  // an out_dir: every announcement is refused).
  std::string CheckpointFolder() const;
  // Offers every checkpoint file of this run in CheckpointFolder() that the history has not
  // scored to the queue (the newest pending, the others in the backlog) and logs how many.
  void QueueUnscoredCheckpoints();
  // Makes the due t-SNE map now (busy, with stats). Returns true when it was written.
  bool MakeTsneMap();
  // MakeTsneMap() when a map is due and the time share allows it; rewrites the report after it.
  // Returns whether it tried.
  bool MakeDueTsneMap();
  // Between episodes: stats when due; Interrupted when a stop was requested.
  void Tick();

  EvaluatorConfig config_;
  Bus* bus_;
  ProgressLog log_;
  std::string report_dir_;  // empty without out_dir
  ReportInfo report_;       // what every report shows (env, run, goal, config, settings)
  EvalHistory history_;
  CheckpointQueue queue_{&history_, config_.backlog};
  SecondMetric second_;
  BestMedia media_;
  TsneScheduler tsne_;
  int64_t scored_ = 0;
  int64_t refused_ = 0;
  int64_t screened_out_ = 0;
  int rejects_in_row_ = 0;  // screen failures since the last full evaluation
  bool busy_ = false;
  double next_stats_time_ = 0;  // MonoSeconds() when stats are due
  // Points at this service while it lives; the bus handler holds a copy.
  std::shared_ptr<EvaluatorService*> alive_ = std::make_shared<EvaluatorService*>(this);
};

}  // namespace rl::evaluator
