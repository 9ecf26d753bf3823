// The run's training metrics (metrics.jsonl, written by the monitor: tools/metrics_log.h) as
// curves against wall time, for the report beside the evaluation curves: is the run learning,
// stalled or diverging, and why (return, loss, Q, exploration, throughput, replay fill).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "evaluator/learning_curve.h"

namespace rl::evaluator {

/// One plot: its file name in the report folder, title, y axis, and points (x = seconds into the
/// run, std 0).
struct TrainingSeries {
  std::string file;
  std::string title;
  std::string y_label;
  std::vector<CurvePoint> points;
};

/// Reads `path` and returns the plots that have points, in a fixed order: training return (the
/// mean of the actors' mean returns), exploration (the actors' mean epsilon or noise scale),
/// env steps/s (summed over the actors), loss, mean Q, updates/s, replay size. Lines that do not
/// parse (a torn last line) are skipped. A missing file gives no plots. O(file size).
std::vector<TrainingSeries> LoadTrainingSeries(const std::string& path);

/// The actors' episodes (all lives) when the learner had made `updates` updates.
struct EpisodesAtUpdate {
  int64_t updates = 0;
  int64_t episodes = 0;
};

/// The episodes of a run's actors in its metrics file, all their lives together: a restarted
/// actor counts from 0 again, so a drop in one actor's count adds the count before it.
struct ActorEpisodes {
  /// One point per learner line after the first actor line, in file order: the learner's
  /// updates and the actors' episodes of the lines before it.
  std::vector<EpisodesAtUpdate> by_update;
  int64_t total = 0;  // by the end of the file
};

/// Reads the metrics file at `path`: empty for a missing file (or an empty path) or one without
/// actors' episodes. Lines that do not parse are skipped. O(file size).
ActorEpisodes LoadActorEpisodes(const std::string& path);

/// The training episodes by the checkpoint at `update`: those of the first point with at least
/// that many updates; nullopt when the points end before it.
std::optional<int64_t> EpisodesAt(const std::vector<EpisodesAtUpdate>& points, int64_t update);

}  // namespace rl::evaluator
