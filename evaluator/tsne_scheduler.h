// When the evaluator makes the t-SNE map of a new best checkpoint (report/tsne.png, tsne_map.h),
// and its caption in the report.
#pragma once

#include <cstdint>
#include <limits>
#include <optional>
#include <string>

#include "evaluator/eval_history.h"
#include "evaluator/progress.h"
#include "evaluator/report.h"
#include "nn/checkpoint.h"
#include "nn/sequential.h"

namespace rl::evaluator {

/// Maps are made after the checkpoint's result is published, and only while all maps, this one's
/// expected duration included, take at most kTsneTimeShare of the evaluator's time since it
/// started; until then the report keeps the last map and the newest best's map stays due (made
/// between later checkpoints when the share allows). A map's expected duration is the last
/// one's, or kTsneFirstGuessSeconds before the first. A checkpoint that reaches the goal, after
/// which the run usually ends, gets its map before its result is published when it is expected
/// to take at most kTsneGoalSeconds: that delays the end of the run by as much, once.
inline constexpr double kTsneTimeShare = 0.2;
inline constexpr double kTsneFirstGuessSeconds = 5.0;
inline constexpr double kTsneGoalSeconds = 15.0;

struct TsneScheduleConfig {
  std::string env_id;
  int states = 0;          // states of a map; 0: no maps
  uint64_t seed_base = 0;  // greedy episode e is reset with seed seed_base + e
  double gamma = 0;        // discount of the returns that colour a TD3 actor's states
  std::string report_dir;  // where the map goes; empty: no maps
  // The best standard-metric mean of the evaluator's earlier life in this run folder (its
  // resumed history): only a checkpoint above it is a new best, and
  // until then the report shows the map that life made.
  double best_before = -std::numeric_limits<double>::infinity();
};

/// Keeps the map of the newest best checkpoint due until the time share allows it. Times are
/// MonoSeconds(). Not thread-safe.
class TsneScheduler {
 public:
  TsneScheduler(TsneScheduleConfig config, ProgressLog log);

  /// Makes the map of the checkpoint `ckpt` (read from `path`) due when `record` is better than
  /// the last best offered (replacing a due map not made yet). A network that does not build is
  /// logged.
  void OfferBest(const nn::Checkpoint& ckpt, const std::string& path, const EvalRecord& record);

  /// Whether a map is due.
  bool due() const { return net_.has_value(); }
  /// Whether the due map fits in the time share now.
  bool fits_share() const;
  /// Whether the due map is expected to take at most kTsneGoalSeconds.
  bool quick() const { return ExpectedSeconds() <= kTsneGoalSeconds; }
  /// Seconds spent on maps so far, aborted ones included.
  double seconds() const { return seconds_; }

  /// Makes the due map now: report/tsne.png and its caption, with a progress line every 5 s
  /// once it has taken 2 s and one when it is written. `tick` is called after every step and
  /// every 50 t-SNE iterations; when it throws Interrupted the map stays due. A map that fails
  /// otherwise is logged and dropped. Returns true when the map was written.
  bool Make(const Tick& tick);

  /// Names the map and its caption in `info` once one was written.
  void AddTo(ReportInfo* info) const;

 private:
  double ExpectedSeconds() const;
  std::string MapPath() const;  // report/tsne.png

  TsneScheduleConfig config_;
  ProgressLog log_;
  double start_time_;                  // when the scheduler was made
  std::optional<nn::Sequential> net_;  // the network of the due map
  EvalRecord record_;                  // and its checkpoint's record
  double best_mean_;
  double seconds_ = 0;       // spent on maps, aborted ones included
  double last_seconds_ = 0;  // the last map written took this long (0: none yet)
  std::string caption_;      // empty until a map was written
};

}  // namespace rl::evaluator
