#include "envs/catch.h"

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <vector>

#include <gtest/gtest.h>

#include "envs/raster.h"
#include "envs/registry.h"
#include "envs/time_limit.h"
#include "tests/envs/image_testing.h"
#include "tests/envs/render_checks.h"

namespace rl::envs {
namespace {

// Index of cell (row, column) in the flat observation.
int Cell(int row, int column) { return row * Catch::kColumns + column; }

// The indices of the observation's non-zero entries (all must be exactly 1).
std::vector<int> Ones(const Catch& env) {
  std::vector<int> ones;
  const auto obs = env.observation();
  for (int i = 0; i < static_cast<int>(obs.size()); ++i) {
    if (obs[i] != 0.0f) {
      EXPECT_EQ(obs[i], 1.0f) << "cell " << i;
      ones.push_back(i);
    }
  }
  return ones;
}

// Action that moves the paddle one column towards `column` (1 = stay when already there).
int Towards(int paddle, int column) { return paddle < column ? 2 : paddle > column ? 0 : 1; }

TEST(CatchTest, ResetPutsTheBallInTheTopRowAndThePaddleInTheMiddleOfTheBottomRow) {
  Catch env;
  env.Reset(3);
  EXPECT_EQ(env.ball_row(), 0);
  EXPECT_GE(env.ball_column(), 0);
  EXPECT_LT(env.ball_column(), 5);
  EXPECT_EQ(env.paddle_column(), 2);
  EXPECT_FALSE(env.episode_over());
  EXPECT_EQ(Ones(env), (std::vector<int>{Cell(0, env.ball_column()), Cell(9, 2)}));
}

TEST(CatchTest, ResetDrawsEveryColumnAboutEquallyOften) {
  Catch env;
  std::array<int, 5> counts{};
  env.Reset(0);
  constexpr int kResets = 5000;
  for (int i = 0; i < kResets; ++i) {
    env.Reset();
    ++counts[static_cast<std::size_t>(env.ball_column())];
  }
  // 1000 expected per column; the standard deviation is sqrt(5000 * 0.2 * 0.8) ~ 28.
  for (int c = 0; c < 5; ++c) {
    EXPECT_GT(counts[static_cast<std::size_t>(c)], 850) << "column " << c;
    EXPECT_LT(counts[static_cast<std::size_t>(c)], 1150) << "column " << c;
  }
  // Seeds alone cover all the columns too.
  std::array<bool, 5> seen{};
  for (uint64_t seed = 0; seed < 100; ++seed) {
    env.Reset(seed);
    seen[static_cast<std::size_t>(env.ball_column())] = true;
  }
  for (int c = 0; c < 5; ++c) EXPECT_TRUE(seen[static_cast<std::size_t>(c)]) << "column " << c;
}

TEST(CatchTest, StepMovesThePaddleThenDropsTheBallOneRow) {
  Catch env;
  env.Reset(1);
  const int ball = env.ball_column();
  // Left from column 2.
  EXPECT_EQ(env.Step(DiscreteAction(0)).reward, 0.0);
  EXPECT_EQ(env.paddle_column(), 1);
  EXPECT_EQ(env.ball_row(), 1);
  EXPECT_EQ(env.ball_column(), ball);
  EXPECT_EQ(Ones(env), (std::vector<int>{Cell(1, ball), Cell(9, 1)}));
  // Stay.
  env.Step(DiscreteAction(1));
  EXPECT_EQ(env.paddle_column(), 1);
  EXPECT_EQ(env.ball_row(), 2);
  // Right twice.
  env.Step(DiscreteAction(2));
  env.Step(DiscreteAction(2));
  EXPECT_EQ(env.paddle_column(), 3);
  EXPECT_EQ(env.ball_row(), 4);
  EXPECT_EQ(Ones(env), (std::vector<int>{Cell(4, ball), Cell(9, 3)}));
}

TEST(CatchTest, PaddleIsClampedToTheGrid) {
  Catch env;
  env.Reset(2);
  for (int t = 0; t < 4; ++t) env.Step(DiscreteAction(0));
  EXPECT_EQ(env.paddle_column(), 0);
  env.Reset(2);
  for (int t = 0; t < 4; ++t) env.Step(DiscreteAction(2));
  EXPECT_EQ(env.paddle_column(), 4);
}

TEST(CatchTest, EveryEpisodeLastsNineStepsAndEndsWithPlusOneForACatch) {
  Catch env;
  for (uint64_t seed = 0; seed < 20; ++seed) {
    env.Reset(seed);
    const int ball = env.ball_column();
    for (int t = 1; t <= 9; ++t) {
      const StepResult r = env.Step(DiscreteAction(Towards(env.paddle_column(), ball)));
      EXPECT_FALSE(r.truncated);
      EXPECT_EQ(r.terminated, t == 9) << "seed " << seed << " step " << t;
      EXPECT_EQ(r.reward, t == 9 ? 1.0 : 0.0) << "seed " << seed << " step " << t;
    }
    EXPECT_TRUE(env.episode_over());
    EXPECT_EQ(env.ball_row(), 9);
    // Ball and paddle share the cell: a single 1 in the observation.
    EXPECT_EQ(Ones(env), (std::vector<int>{Cell(9, ball)}));
  }
}

TEST(CatchTest, MissingTheBallEndsWithMinusOne) {
  Catch env;
  for (uint64_t seed = 0; seed < 20; ++seed) {
    env.Reset(seed);
    const int ball = env.ball_column();
    // Move to the far side from the ball: column 0 if the ball is right of the middle, else 4.
    const int away = ball >= 2 ? 0 : 4;
    StepResult r;
    for (int t = 1; t <= 9; ++t) r = env.Step(DiscreteAction(Towards(env.paddle_column(), away)));
    EXPECT_TRUE(r.terminated);
    EXPECT_EQ(r.reward, -1.0) << "seed " << seed;
    EXPECT_EQ(env.paddle_column(), away);
    EXPECT_EQ(Ones(env),
              (std::vector<int>{Cell(9, std::min(away, ball)), Cell(9, std::max(away, ball))}));
  }
}

TEST(CatchTest, SameSeedGivesTheSameEpisodes) {
  Catch a;
  Catch b;
  for (uint64_t seed : {0u, 7u, 123456789u}) {
    a.Reset(seed);
    b.Reset(seed);
    for (int episode = 0; episode < 5; ++episode) {
      if (episode > 0) {
        a.Reset();
        b.Reset();
      }
      EXPECT_EQ(a.ball_column(), b.ball_column());
      for (int t = 0; t < 9; ++t) {
        const int action = (t + episode) % 3;
        const StepResult ra = a.Step(DiscreteAction(action));
        const StepResult rb = b.Step(DiscreteAction(action));
        EXPECT_EQ(ra.reward, rb.reward);
        EXPECT_EQ(ra.terminated, rb.terminated);
        ASSERT_TRUE(
            std::equal(a.observation().begin(), a.observation().end(), b.observation().begin()));
      }
    }
  }
  // Different seeds give different first columns for some seed pair.
  std::vector<int> columns;
  for (uint64_t seed = 0; seed < 10; ++seed) {
    a.Reset(seed);
    columns.push_back(a.ball_column());
  }
  EXPECT_NE(std::count(columns.begin(), columns.end(), columns[0]), 10);
}

TEST(CatchTest, BadActionsAndStepsOutsideAnEpisodeThrowWithoutChangingTheState) {
  Catch env;
  EXPECT_THROW(env.Step(DiscreteAction(1)), std::logic_error);
  env.Reset(4);
  EXPECT_THROW(env.Step(DiscreteAction(-1)), std::invalid_argument);
  EXPECT_THROW(env.Step(DiscreteAction(3)), std::invalid_argument);
  EXPECT_EQ(env.ball_row(), 0);
  EXPECT_EQ(env.paddle_column(), 2);
  for (int t = 0; t < 9; ++t) env.Step(DiscreteAction(1));
  EXPECT_THROW(env.Step(DiscreteAction(1)), std::logic_error);
  EXPECT_EQ(env.ball_row(), 9);
  env.Reset();
  EXPECT_EQ(env.ball_row(), 0);
  EXPECT_NO_THROW(env.Step(DiscreteAction(1)));
}

TEST(CatchTest, RenderIs40By80WithWhiteBallAndPaddleCellsOnBlack) {
  Catch env;
  ExpectRenderRefusedBeforeReset(env);
  env.Reset(5);
  env.Step(DiscreteAction(0));  // Paddle to column 1, ball to row 1.
  const Image image = Rendered(env);
  ASSERT_EQ(image.width, 40);
  ASSERT_EQ(image.height, 80);
  ASSERT_EQ(image.rgb.size(), 40u * 80u * 3u);
  // Two 8x8 white squares: the ball at x in [8c, 8c + 8), y in [8, 16); the paddle at
  // x in [8, 16), y in [72, 80). Everything else is black.
  const int ball_x = 8 * env.ball_column();
  EXPECT_EQ(FindColor(image, kWhite).count, 2 * 64);
  EXPECT_EQ(FindColor(image, kBlack).count, 40 * 80 - 2 * 64);
  for (int y = 0; y < 8; ++y) {
    for (int x = 0; x < 8; ++x) {
      EXPECT_EQ(image.at(ball_x + x, 8 + y), kWhite);
      EXPECT_EQ(image.at(8 + x, 72 + y), kWhite);
    }
  }
}

TEST(CatchTest, RenderSizedPutsCellBoundariesAtFloorOfTheScaledGrid) {
  Catch env;
  env.Reset(6);
  const int ball = env.ball_column();
  // 13 x 23: column c spans [floor(13c / 5), floor(13(c + 1) / 5)), i.e. the column edges are
  // 0, 2, 5, 7, 10, 13; the row edges are floor(23r / 10): 0, 2, 4, 6, 9, 11, 13, 16, 18, 20, 23.
  constexpr std::array<int, 6> kColumnEdges = {0, 2, 5, 7, 10, 13};
  const Image image = RenderedSized(env, 13, 23);
  ASSERT_EQ(image.rgb.size(), 13u * 23u * 3u);
  for (int y = 0; y < 23; ++y) {
    for (int x = 0; x < 13; ++x) {
      const bool in_ball = y < 2 && x >= kColumnEdges[static_cast<std::size_t>(ball)] &&
                           x < kColumnEdges[static_cast<std::size_t>(ball) + 1];
      const bool in_paddle = y >= 20 && x >= 5 && x < 7;  // Row 9, column 2.
      EXPECT_EQ(image.at(x, y), in_ball || in_paddle ? kWhite : kBlack) << x << "," << y;
    }
  }
  // At the native size RenderSized is Render.
  EXPECT_EQ(RenderedSized(env, 40, 80).rgb, Rendered(env).rgb);
  std::vector<uint8_t> rgb;
  EXPECT_THROW(env.RenderSized(0, 10, &rgb), std::invalid_argument);
}

TEST(CatchTest, RegistryWrapsCatchInANineStepTimeLimit) {
  auto env = MakeEnv("Catch-v0");
  EXPECT_EQ(env->spec().id, "Catch-v0");
  EXPECT_EQ(env->spec().max_episode_steps, 9);
  auto* limit = dynamic_cast<TimeLimit*>(env.get());
  ASSERT_NE(limit, nullptr);
  EXPECT_NE(dynamic_cast<Catch*>(&limit->wrapped_env()), nullptr);
  // The limit coincides with the natural end of the episode.
  env->Reset(0);
  for (int t = 1; t < 9; ++t) {
    const StepResult r = env->Step(DiscreteAction(1));
    EXPECT_FALSE(r.terminated || r.truncated) << "step " << t;
  }
  const StepResult last = env->Step(DiscreteAction(1));
  EXPECT_TRUE(last.terminated);
  EXPECT_TRUE(last.truncated);
}

}  // namespace
}  // namespace rl::envs
