// A grid of sample camera frames for the report of a pixel env: one row per greedy episode, one
// cell per step, each cell the env's camera image as rendered (left) beside the frame the network
// receives after the image pipeline (right), both scaled up to the same height by pixel
// replication, under a label with the step (and the return on the episode's last cell).
#pragma once

#include <cstdint>
#include <string>

#include "evaluator/progress.h"
#include "nn/sequential.h"

namespace rl::evaluator {

/// Height in pixels of both images of a cell, and of the label above them.
inline constexpr int kFrameGridImageHeight = 96;
inline constexpr int kFrameGridLabelHeight = 16;
/// Pixels between the two images of a cell, between cells and between rows.
inline constexpr int kFrameGridGap = 4;

struct FrameGridResult {
  int episodes = 0;           // rows
  int columns = 0;            // cells in the longest row
  double mean_return = 0;     // mean return of the episodes shown
  int width = 0, height = 0;  // size of the PNG
};

/// Plays `episodes` episodes of `env_id` (episode i reset with seed + i) greedily with `net` and
/// writes the grid to `path` as PNG, atomically. A row shows the state after Reset and after
/// each step; episodes longer than `max_columns` cells keep their first max_columns - 1 cells and
/// their last. Throws std::invalid_argument when the env has no frames (not a pixel env), the
/// network does not fit the env, or episodes or max_columns is below 1 (max_columns below 2);
/// std::runtime_error when the PNG cannot be encoded or written. Memory: O(episodes x max_columns)
/// cells of about 25 KB.
/// `tick` (when set) is called after every step (progress.h).
FrameGridResult WriteFrameGrid(nn::Sequential* net, const std::string& env_id, uint64_t seed,
                               int episodes, int max_columns, const std::string& path,
                               const Tick& tick = {});

}  // namespace rl::evaluator
