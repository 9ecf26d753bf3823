// The run's evaluation history: eval.jsonl, one JSON line per scored checkpoint, appended and
// synced, so that a restarted evaluator keeps the history and the report and the compare page
// read it back.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace rl::evaluator {

/// The file of the run's folder that keeps the network of the best average of weights
/// (EvaluatorConfig::ensemble_by "weights"): a checkpoint file like the learner's.
inline constexpr char kBestAverageFile[] = "best-average.bin";

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
  // The mean action of this checkpoint and the ensemble_size - 1 checkpoints before it in the
  // run's folder (EvaluatorConfig::ensemble), the oldest at update ensemble_from, scored on the
  // same episodes as the checkpoint; ensemble_size 0: not scored.
  // ensemble_by "weights": instead the network of their mean weights (AverageCheckpoints).
  int ensemble_size = 0;
  std::string ensemble_by;  // "actions" or "weights" when ensemble_size > 0
  int64_t ensemble_from = 0;
  double ensemble_mean = 0;
  double ensemble_std = 0;
  double ensemble_min = 0;
  double ensemble_max = 0;
  std::vector<double> ensemble_returns;  // each episode's return, in episode order
  // Each evaluation episode's return, in episode order: how a mean was made (a few failed
  // episodes or a uniform shortfall). Empty in lines written before they were kept.
  std::vector<double> returns;
  // Each evaluation episode's env steps, in episode order: with the env's time limit, which
  // episodes ended early (a lap finished, a crash) and which ran out of time. Empty as above.
  std::vector<int> steps;
  // Continuous actions: each component's mean over every step of the episodes, as the policy
  // gave it (e.g. CarRacing's steer, gas and brake): what the policy does. Empty for discrete
  // actions and in lines written before it was kept.
  std::vector<double> action_mean;

  bool operator==(const EvalRecord&) const = default;
};

/// One line of eval.jsonl, without the newline: {"checkpoint": ..., "update": ..., "env_steps":
/// ..., "wall_seconds": ..., "mean": ..., "std": ..., "min": ..., "max": ..., "episodes": ...,
/// "eval_seconds": ...}, and when value_steps > 0 also "value_steps", "value_estimate",
/// "value_return" and "value_correlation" (null when unset), and when second_episodes > 0
/// "second_mean", "second_std" and "second_episodes", when ensemble_size > 0 "ensemble_size",
/// "ensemble_by", "ensemble_from", "ensemble_mean", "ensemble_std", "ensemble_min",
/// "ensemble_max" and "ensemble_returns", and last, when there are any, "returns", "steps" and
/// "action_mean" (arrays) (json_line.h: numbers in their shortest form that reads back exactly; a
/// non-finite number is written as null).
std::string ToJson(const EvalRecord& record);

/// Parses one line written by ToJson (keys in any order, unknown keys ignored, whitespace
/// allowed). Returns false, leaving *record unchanged, when the line is not such an object or
/// lacks "checkpoint", "update" or "mean". "returns" that is not an array of numbers, or
/// "steps" that is not one of whole numbers from 0, or "action_mean" that is not an array of
/// numbers, is read as none.
bool ParseJson(const std::string& line, EvalRecord* record);

/// Appends ToJson(record) and a newline to the file at `path` (created if missing), then
/// flushes and fsyncs it. Throws std::runtime_error naming the file on an I/O error.
void AppendJsonLine(const std::string& path, const EvalRecord& record);

/// Reads the records of an eval.jsonl. A missing file gives no records; a line that does not
/// parse (such as a line torn by a crash) is skipped and counted in *skipped_lines if given.
std::vector<EvalRecord> LoadJsonLines(const std::string& path, int* skipped_lines = nullptr);

/// The records of a run, in scoring order, kept in memory and (with a path) in eval.jsonl.
/// Not thread-safe.
class EvalHistory {
 public:
  /// No file: the records live in memory only.
  EvalHistory() = default;
  /// Loads the existing records of `jsonl_path` (LoadJsonLines: unreadable lines are skipped and
  /// counted); Add() appends to it.
  explicit EvalHistory(std::string jsonl_path);

  /// Keeps `record` and appends its line to the file. Throws std::runtime_error when the line
  /// cannot be written (the record is kept in memory all the same).
  void Add(const EvalRecord& record);

  /// Whether a record of this checkpoint file name and update is kept.
  bool Contains(const std::string& checkpoint, int64_t update) const;
  /// The first record with the highest mean, or nullptr when there is none.
  const EvalRecord* best() const;
  const std::vector<EvalRecord>& records() const { return records_; }
  /// Lines of the file that did not parse when it was loaded.
  int skipped_lines() const { return skipped_lines_; }
  /// The file; empty without one.
  const std::string& path() const { return path_; }

 private:
  std::string path_;
  std::vector<EvalRecord> records_;
  int skipped_lines_ = 0;
};

}  // namespace rl::evaluator
