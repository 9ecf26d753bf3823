#include "envs/catch.h"

#include <algorithm>
#include <cstddef>
#include <stdexcept>
#include <string>

#include "common/check.h"
#include "envs/env_list.h"
#include "envs/raster.h"
#include "envs/render_args.h"
#include "envs/rng.h"
#include "envs/specs.h"

namespace rl::envs {
namespace {

constexpr Rgb kBackground{0, 0, 0};
constexpr Rgb kObject{255, 255, 255};

// Paints grid cell (row, column) of a width x height canvas; the cell boundaries are
// floor(i * size / cells), computed in 64 bits so that large sizes cannot overflow.
void PaintCell(Canvas& canvas, int row, int column) {
  const auto edge = [](int i, int size, int cells) {
    return static_cast<int>(static_cast<int64_t>(i) * size / cells);
  };
  const int w = canvas.width();
  const int h = canvas.height();
  canvas.FillPixelRect(edge(column, w, Catch::kColumns), edge(row, h, Catch::kRows),
                       edge(column + 1, w, Catch::kColumns), edge(row + 1, h, Catch::kRows),
                       kObject);
}

}  // namespace

Catch::Catch() : SeededEnv(CatchSpec()) {
  RL_CHECK(spec().observation_size == kRows * kColumns && spec().max_episode_steps == kRows - 1 &&
           spec().render_width == kScreenWidth && spec().render_height == kScreenHeight)
      << "CatchSpec() disagrees with the Catch constants";
}

void Catch::NewEpisode() {
  ball_column_ = static_cast<int>(UniformInt(rng(), 0, kColumns));
  ball_row_ = 0;
  paddle_column_ = kPaddleStartColumn;
  UpdateObservation();
}

StepResult Catch::OnStep(std::span<const float> action) {
  if (ball_row_ == kRows - 1) {
    throw std::logic_error(
        "Catch: the episode is over (the ball is in the bottom row); call Reset()");
  }

  // Move the paddle (action 0, 1, 2 -> -1, 0, +1 columns), then drop the ball one row.
  paddle_column_ = std::clamp(paddle_column_ + ActionIndex(action) - 1, 0, kColumns - 1);
  ++ball_row_;
  UpdateObservation();

  // The episode ends when the ball reaches the paddle's row.
  StepResult result;
  if (ball_row_ == kRows - 1) {
    result.terminated = true;
    result.reward = paddle_column_ == ball_column_ ? 1.0 : -1.0;
  }
  return result;
}

void Catch::UpdateObservation() {
  std::fill(observation_.begin(), observation_.end(), 0.0f);
  const int ball = ball_row_ * kColumns + ball_column_;
  const int paddle = (kRows - 1) * kColumns + paddle_column_;
  observation_[static_cast<std::size_t>(ball)] = 1.0f;
  observation_[static_cast<std::size_t>(paddle)] = 1.0f;
}

void Catch::Render(std::vector<uint8_t>* rgb, int* width, int* height) const {
  RenderNative(*this, kScreenWidth, kScreenHeight, rgb, width, height);
}

void Catch::RenderSized(int width, int height, std::vector<uint8_t>* rgb) const {
  CheckRenderArgs(*this, "Catch", width, height, rgb);

  // Black board with the ball's and the paddle's cells in white.
  Canvas canvas(width, height, rgb);
  canvas.Clear(kBackground);
  PaintCell(canvas, ball_row_, ball_column_);
  PaintCell(canvas, kRows - 1, paddle_column_);
}

// Registered as Catch-v0 (env_list.inc). Every episode ends after 9 steps, so the time limit
// never cuts one short: it only marks the terminating step truncated as well (terminated still
// means no bootstrapping).
std::unique_ptr<Env> MakeCatchV0(const EnvIdParts&) { return std::make_unique<Catch>(); }

}  // namespace rl::envs
