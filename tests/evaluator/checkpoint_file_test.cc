// Scoring checkpoint files: an ensemble is a checkpoint and the ones before it in its folder.
#include "evaluator/checkpoint_file.h"

#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "constant_lander.h"
#include "nn/checkpoint.h"
#include "tests/common/temp_dir.h"

namespace rl::evaluator {
namespace {

using testing::ConstantLanderCheckpoint;
using testing::kLander;

class EnsembleFilesTest : public TempDirTest {
 protected:
  EnsembleFilesTest() {
    for (int64_t update : {10, 20, 30, 40}) {
      nn::SaveCheckpoint(Path(update), ConstantLanderCheckpoint(update, 0.6f, -0.4f));
    }
    nn::SaveCheckpoint((dir_ / "learner-state.bin").string(), ConstantLanderCheckpoint(0, 0, 0));
  }
  std::string Path(int64_t update) const {
    return (dir_ / nn::CheckpointFileName(update)).string();
  }
};

TEST_F(EnsembleFilesTest, TakesTheCheckpointAndTheOnesBeforeItNewestFirst) {
  EXPECT_EQ(EnsembleFiles(Path(30), 3), (std::vector<std::string>{Path(30), Path(20), Path(10)}));
  EXPECT_EQ(EnsembleFiles(Path(40), 1), std::vector<std::string>{Path(40)});
  EXPECT_THROW(EnsembleFiles(Path(20), 3), std::runtime_error);  // one before it, not two
  EXPECT_THROW(EnsembleFiles((dir_ / "learner-state.bin").string(), 1), std::runtime_error);
  EXPECT_THROW(EnsembleFiles(Path(40), 0), std::invalid_argument);
}

// The record is the newest checkpoint's, scored with the members' mean action: the same as one
// checkpoint of that action.
TEST_F(EnsembleFilesTest, ScoresTheMeanActionUnderTheNewestCheckpointsName) {
  nn::SaveCheckpoint(Path(50), ConstantLanderCheckpoint(50, 0.2f, 0.0f));
  const std::string single = (dir_ / "single" / nn::CheckpointFileName(7)).string();
  std::filesystem::create_directory(dir_ / "single");
  nn::SaveCheckpoint(single, ConstantLanderCheckpoint(7, (0.6f + 0.2f) / 2, (-0.4f + 0.0f) / 2));
  const EvalRecord ensemble = ScoreEnsembleFiles(EnsembleFiles(Path(50), 2), kLander, 2, 40);
  EXPECT_EQ(ensemble.checkpoint, nn::CheckpointFileName(50));
  EXPECT_EQ(ensemble.update, 50);
  EXPECT_EQ(ensemble.env_steps, 100);
  EXPECT_EQ(ensemble.returns, ScoreCheckpointFile(single, kLander, 2, 0.0, 40).returns);
  EXPECT_NE(ensemble.returns, ScoreCheckpointFile(Path(50), kLander, 2, 0.0, 40).returns);
  EXPECT_THROW(ScoreEnsembleFiles({}, kLander, 2, 40), std::invalid_argument);
  EXPECT_THROW(ScoreEnsembleFiles({Path(50)}, "CartPole-v1", 2, 40), std::runtime_error);
}

}  // namespace
}  // namespace rl::evaluator
