// Scoring checkpoint files: an ensemble is a checkpoint and the ones before it in its folder,
// played by their mean action or averaged into one network.
#include "evaluator/checkpoint_file.h"

#include <filesystem>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "constant_lander.h"
#include "nn/checkpoint.h"
#include "nn/sequential.h"
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

// The mean of the members' parameters, under the newest one's architecture and metadata.
TEST(AverageCheckpointsTest, AveragesTheWeightsOfOneRunsNetworks) {
  nn::Checkpoint a = ConstantLanderCheckpoint(20, 0.6f, -0.4f, 9);
  nn::Checkpoint b = ConstantLanderCheckpoint(10, 0.2f, 0.0f, 9);
  b.params[3] = 1.0f;  // a weight, not only the biases
  a.meta.note = "run notes";
  const nn::Checkpoint average = AverageCheckpoints({a, b}, {"a.bin", "b.bin"});
  EXPECT_EQ(average.architecture, a.architecture);
  EXPECT_EQ(average.meta.update, 20);
  EXPECT_EQ(average.meta.env_steps, 40);
  EXPECT_EQ(average.meta.run_id, 9U);
  EXPECT_EQ(average.meta.note, "The mean weights of 2 checkpoints, updates 10 to 20.\nrun notes");
  ASSERT_EQ(average.params.size(), a.params.size());
  for (size_t i = 0; i < a.params.size(); ++i) {
    EXPECT_FLOAT_EQ(average.params[i], (a.params[i] + b.params[i]) / 2) << i;
  }
  EXPECT_FLOAT_EQ(average.params[3], 0.5f);
  EXPECT_EQ(AverageCheckpoints({a}, {"a.bin"}).params, a.params);
}

TEST(AverageCheckpointsTest, RefusesAnotherRunOrNetwork) {
  const nn::Checkpoint a = ConstantLanderCheckpoint(20, 0.6f, -0.4f, 9);
  EXPECT_THROW(AverageCheckpoints({}, {}), std::invalid_argument);
  EXPECT_THROW(AverageCheckpoints({a, a}, {"a.bin"}), std::invalid_argument);
  try {
    AverageCheckpoints({a, ConstantLanderCheckpoint(10, 0, 0, 8)}, {"a.bin", "other-run.bin"});
    ADD_FAILURE() << "another run's checkpoint was averaged";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("other-run.bin is of run 8, not 9"), std::string::npos)
        << e.what();
  }
  std::mt19937 rng(1);
  const nn::Sequential wider = nn::MakeMlp(8, {5}, 2, &rng);
  nn::Checkpoint other = a;
  other.architecture = wider.Architecture();
  wider.GetFlat(&other.params);
  EXPECT_THROW(AverageCheckpoints({a, other}, {"a.bin", "wider.bin"}), std::runtime_error);
}

// An average of weights is scored as the one checkpoint it is (as the service and the
// standalone mode score it); for these constant actors that is also their mean action.
TEST_F(EnsembleFilesTest, ScoresTheAverageAsTheCheckpointOfTheMeanWeights) {
  nn::SaveCheckpoint(Path(50), ConstantLanderCheckpoint(50, 0.2f, 0.0f));
  const std::vector<std::string> files = EnsembleFiles(Path(50), 2);
  const std::vector<nn::Checkpoint> members = {nn::LoadCheckpoint(files[0]),
                                               nn::LoadCheckpoint(files[1])};
  const EvalRecord average =
      ScoreCheckpoint(AverageCheckpoints(members, files), files[0], kLander, 2, 0.0, 40);
  EXPECT_EQ(average.checkpoint, nn::CheckpointFileName(50));
  EXPECT_EQ(average.update, 50);
  EXPECT_EQ(average.returns, ScoreEnsembleFiles(files, kLander, 2, 40).returns);
  EXPECT_EQ(average.returns,
            ScoreCheckpoint(ConstantLanderCheckpoint(7, 0.4f, -0.2f), "m.bin", kLander, 2, 0.0, 40)
                .returns);
}

}  // namespace
}  // namespace rl::evaluator
