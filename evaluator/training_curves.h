// The run's training metrics (metrics.jsonl, written by the monitor: tools/metrics_log.h) as
// curves against wall time, for the report beside the evaluation curves: is the run learning,
// stalled or diverging, and why (return, loss, Q, exploration, throughput, replay fill).
#pragma once

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

}  // namespace rl::evaluator
