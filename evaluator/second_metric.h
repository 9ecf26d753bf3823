// The second metric beside the standard one (EvaluatorConfig::second_env): new best checkpoints
// are also scored on another env that takes the same observations and actions (e.g. the rules
// a paper trained and tested with), and their records carry both scores.
#pragma once

#include <cstdint>
#include <limits>
#include <string>
#include <utility>

#include "evaluator/eval_history.h"
#include "evaluator/progress.h"
#include "nn/checkpoint.h"

namespace rl::evaluator {

struct SecondMetricConfig {
  std::string env_id;  // empty: no second metric
  int episodes = 100;
  double epsilon = 0;
  uint64_t seed_base = 0;  // episode i is reset with seed seed_base + i
  double gamma = 0;
  // A new best below this standard-metric mean is not scored.
  double min_mean = -std::numeric_limits<double>::infinity();
  // The best standard-metric mean of the evaluator's earlier life in this run folder (its
  // resumed history): only a checkpoint above it is a new best.
  double best_before = -std::numeric_limits<double>::infinity();
};

/// Scores new best checkpoints on the second env. Not thread-safe.
class SecondMetric {
 public:
  SecondMetric(SecondMetricConfig config, ProgressLog log)
      : config_(std::move(config)), log_(log), best_mean_(config_.best_before) {}

  /// When `record` (scored on the standard metric) is a new best at config.min_mean or more, scores
  /// the checkpoint `ckpt` (read from `path`) on the second env into record's second_* fields and
  /// prints a progress line; nothing otherwise or without a second env. A file that fails to score
  /// is logged, and a stop request (Interrupted from `tick`, after a step) ends the scoring: both
  /// leave the record as it is.
  void ScoreIfBest(const nn::Checkpoint& ckpt, const std::string& path, EvalRecord* record,
                   const Tick& tick);

  bool enabled() const { return !config_.env_id.empty(); }

 private:
  SecondMetricConfig config_;
  ProgressLog log_;
  double best_mean_;  // on the standard metric
};

}  // namespace rl::evaluator
