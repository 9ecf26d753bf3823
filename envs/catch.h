// Catch: a ball falls one row per step down a grid of 10 rows x 5 columns; move the paddle along
// the bottom row so that the ball lands on it. A tiny env for testing the pixel pipeline
// (envs/image/): its pictures are a few white cells on black, so where the ball and the paddle
// must appear in a processed frame can be worked out by hand.
//
// Behaves like DeepMind bsuite's Catch:
// https://github.com/google-deepmind/bsuite/blob/master/bsuite/environments/catch.py
// Differences: bsuite starts a new episode by itself after the last step; here Step after the last
// step throws and the caller resets, as for the other envs. The time limit of 9 steps is not part
// of this class: MakeEnv("Catch-v0") wraps it in TimeLimit.
#pragma once

#include <array>
#include <cstdint>
#include <random>
#include <span>
#include <vector>

#include "envs/env.h"
#include "envs/rng.h"

namespace rl::envs {

/// Catch-v0. Rows are numbered from the top (row 0) to the bottom (row kRows - 1), columns from the
/// left. At Reset the ball is in row 0 at a uniformly random column and the paddle in the bottom
/// row at column kColumns / 2 (2). Actions: 0 moves the paddle one column left, 1 keeps it, 2 moves
/// it one column right (clamped to the grid). Each Step moves the paddle, then the ball down one
/// row; when the ball reaches the bottom row the episode terminates with reward +1 if the paddle is
/// in the ball's column and -1 otherwise. All other steps give 0, so every episode has exactly
/// kRows - 1 = 9 steps. Copyable (the copy continues the same RNG stream). Not thread-safe.
class Catch : public SeededEnv {
 public:
  static constexpr int kRows = 10;
  static constexpr int kColumns = 5;
  static constexpr int kPaddleStartColumn = kColumns / 2;
  // Native rendering: each cell is kCellPixels x kCellPixels pixels, so the image is 40 x 80.
  static constexpr int kCellPixels = 8;
  static constexpr int kScreenWidth = kColumns * kCellPixels;
  static constexpr int kScreenHeight = kRows * kCellPixels;

  Catch();

  // Spec: id "Catch-v0", observation_size 50, num_actions 3, max_episode_steps 9,
  // reward_threshold 0.9. Reset draws the ball's column with one UniformInt(0, 5). Step moves the
  // paddle, then the ball (see the class comment); besides Env::Step's errors it throws
  // std::logic_error after the episode's last step (state unchanged). truncated is always false
  // (see TimeLimit).

  /// kRows * kColumns floats, row-major: 1.0 in the ball's cell and in the paddle's cell, 0
  /// elsewhere (a single 1.0 when they share the bottom-row cell).
  std::span<const float> observation() const override { return observation_; }

  /// 40 x 80 RGB image: black background, the ball's and the paddle's cells white. Throws
  /// std::logic_error before the first Reset.
  void Render(std::vector<uint8_t>* rgb, int* width, int* height) const override;
  /// Draws the same picture directly at width x height: cell (row r, column c) covers the pixel
  /// columns [floor(c * width / 5), floor((c + 1) * width / 5)) and the pixel rows
  /// [floor(r * height / 10), floor((r + 1) * height / 10)), so the cells tile the image exactly
  /// (a cell is empty when the image is narrower or lower than the grid). Does not allocate when
  /// *rgb already has the size. Throws std::invalid_argument for a non-positive size and
  /// std::logic_error before the first Reset.
  void RenderSized(int width, int height, std::vector<uint8_t>* rgb) const override;

  /// Position of the ball (row 0 at Reset, kRows - 1 when the episode is over) and of the paddle.
  int ball_row() const { return ball_row_; }
  int ball_column() const { return ball_column_; }
  int paddle_column() const { return paddle_column_; }
  /// True once the episode's last step has been taken.
  bool episode_over() const { return started() && ball_row_ == kRows - 1; }

 private:
  void NewEpisode() override;
  StepResult OnStep(std::span<const float> action) override;
  // Refreshes observation_ from the positions.
  void UpdateObservation();

  int ball_row_ = 0;
  int ball_column_ = 0;
  int paddle_column_ = kPaddleStartColumn;
  std::array<float, kRows * kColumns> observation_{};
};

}  // namespace rl::envs
