#include "nn/checkpoint.h"

#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "nn/presets.h"
#include "nn/sequential.h"
#include "tests/common/error_of.h"
#include "tests/common/temp_dir.h"

namespace rl::nn {
namespace {

namespace fs = std::filesystem;

class CheckpointTest : public TempDirTest {
 protected:
  static Checkpoint MakeCheckpoint() {
    std::mt19937 rng(17);
    const Sequential net = MakeMlp(4, {16}, 2, &rng);
    Checkpoint ckpt;
    ckpt.architecture = net.Architecture();
    net.GetFlat(&ckpt.params);
    ckpt.meta.update = 123456789012;
    ckpt.meta.env_steps = -5;
    ckpt.meta.wall_seconds = 3600.25;
    ckpt.meta.run_id = 0xFEDCBA9876543210ULL;
    ckpt.meta.note = std::string("lr=0.001\ngamma=0.99\0tail", 25);
    return ckpt;
  }

  std::vector<char> ReadBytes() const {
    std::ifstream in(path_, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  }
  void WriteBytes(const std::vector<char>& bytes) const {
    std::ofstream out(path_, std::ios::binary | std::ios::trunc);
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  }
  std::vector<std::string> DirectoryEntries() const {
    std::vector<std::string> names;
    for (const auto& entry : fs::directory_iterator(dir_)) {
      names.push_back(entry.path().filename().string());
    }
    return names;
  }
  // The message of the error LoadCheckpoint throws, which must be a std::runtime_error.
  std::string LoadError() const {
    EXPECT_THROW(LoadCheckpoint(path_), std::runtime_error);
    return ErrorOf([this] { LoadCheckpoint(path_); });
  }

  const std::string path_ = (dir_ / "model.ckpt").string();
};

TEST_F(CheckpointTest, RoundTripsEveryField) {
  Checkpoint ckpt = MakeCheckpoint();
  ckpt.params[3] = std::numeric_limits<float>::infinity();
  ckpt.params[4] = -0.0f;
  SaveCheckpoint(path_, ckpt);
  const Checkpoint loaded = LoadCheckpoint(path_);
  EXPECT_EQ(loaded.architecture, ckpt.architecture);
  EXPECT_EQ(loaded.meta.update, ckpt.meta.update);
  EXPECT_EQ(loaded.meta.env_steps, ckpt.meta.env_steps);
  EXPECT_EQ(loaded.meta.wall_seconds, ckpt.meta.wall_seconds);
  EXPECT_EQ(loaded.meta.run_id, ckpt.meta.run_id);
  EXPECT_EQ(loaded.meta.note, ckpt.meta.note);
  ASSERT_EQ(loaded.params.size(), ckpt.params.size());
  EXPECT_EQ(std::memcmp(loaded.params.data(), ckpt.params.data(), ckpt.params.size() * 4), 0);
}

TEST_F(CheckpointTest, RestoredNetworkComputesTheSameOutputs) {
  std::mt19937 rng(3);
  Sequential net = MakeMlp(4, {120, 84}, 2, &rng);
  Checkpoint ckpt;
  ckpt.architecture = net.Architecture();
  net.GetFlat(&ckpt.params);
  SaveCheckpoint(path_, ckpt);

  const Checkpoint loaded = LoadCheckpoint(path_);
  std::mt19937 other_rng(99);
  Sequential restored = BuildFromArchitecture(loaded.architecture, &other_rng);
  restored.SetFlat(loaded.params.data(), loaded.params.size());
  const Matrix x = Matrix::Random(4, 16);
  EXPECT_EQ(Matrix(net.Forward(x)), restored.Forward(x));
}

TEST_F(CheckpointTest, SaveLeavesOnlyTheTargetFileAndReplacesAnOldOne) {
  Checkpoint ckpt = MakeCheckpoint();
  SaveCheckpoint(path_, ckpt);
  ckpt.meta.update = 7;
  SaveCheckpoint(path_, ckpt);
  EXPECT_EQ(DirectoryEntries(), std::vector<std::string>{"model.ckpt"});
  EXPECT_EQ(LoadCheckpoint(path_).meta.update, 7);
}

TEST_F(CheckpointTest, FailedSaveThrowsAndRemovesItsTemporaryFile) {
  // A non-empty directory at the target path makes the final rename fail.
  fs::create_directory(path_);
  std::ofstream(fs::path(path_) / "occupied") << "x";
  try {
    SaveCheckpoint(path_, MakeCheckpoint());
    ADD_FAILURE() << "no exception";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(path_), std::string::npos) << e.what();
  }
  EXPECT_EQ(DirectoryEntries(), std::vector<std::string>{"model.ckpt"});
  EXPECT_TRUE(fs::is_directory(path_));
}

TEST_F(CheckpointTest, SaveIntoAMissingDirectoryThrowsWithTheReason) {
  const std::string path = (dir_ / "no_such_dir" / "model.ckpt").string();
  try {
    SaveCheckpoint(path, MakeCheckpoint());
    ADD_FAILURE() << "no exception";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("No such file or directory"), std::string::npos)
        << e.what();
  }
}

TEST_F(CheckpointTest, RefusesAFlippedByteAsCorrupted) {
  SaveCheckpoint(path_, MakeCheckpoint());
  std::vector<char> bytes = ReadBytes();
  bytes[bytes.size() / 2] ^= 0x10;
  WriteBytes(bytes);
  const std::string error = LoadError();
  EXPECT_NE(error.find("corrupted"), std::string::npos) << error;
  EXPECT_NE(error.find(path_), std::string::npos) << error;
}

TEST_F(CheckpointTest, RefusesATruncatedFile) {
  SaveCheckpoint(path_, MakeCheckpoint());
  std::vector<char> bytes = ReadBytes();
  for (size_t keep : {bytes.size() - 1, bytes.size() / 2, size_t{10}, size_t{0}}) {
    WriteBytes(std::vector<char>(bytes.begin(), bytes.begin() + static_cast<int64_t>(keep)));
    const std::string error = LoadError();
    EXPECT_NE(error.find("truncated"), std::string::npos) << keep << " bytes: " << error;
  }
}

TEST_F(CheckpointTest, RefusesRandomBytesAsNotACheckpoint) {
  std::mt19937 rng(8);
  std::vector<char> bytes(1000);
  for (char& b : bytes) b = static_cast<char>(rng() & 0xFF);
  WriteBytes(bytes);
  const std::string error = LoadError();
  EXPECT_NE(error.find("not a checkpoint"), std::string::npos) << error;
}

TEST_F(CheckpointTest, RefusesAMissingFile) {
  const std::string error = LoadError();
  EXPECT_NE(error.find(path_), std::string::npos) << error;
  EXPECT_NE(error.find("No such file or directory"), std::string::npos) << error;
}

TEST_F(CheckpointTest, RefusesAnUnsupportedVersion) {
  SaveCheckpoint(path_, MakeCheckpoint());
  std::vector<char> bytes = ReadBytes();
  bytes[8] = 2;  // The version follows the 8-byte magic.
  WriteBytes(bytes);
  const std::string error = LoadError();
  EXPECT_NE(error.find("unsupported format version 2"), std::string::npos) << error;
}

TEST_F(CheckpointTest, RefusesParametersThatDoNotMatchTheArchitecture) {
  Checkpoint ckpt = MakeCheckpoint();
  ckpt.params.pop_back();
  SaveCheckpoint(path_, ckpt);
  const std::string error = LoadError();
  EXPECT_NE(error.find("parameters but"), std::string::npos) << error;
}

TEST_F(CheckpointTest, RefusesAnUnknownArchitecture) {
  Checkpoint ckpt = MakeCheckpoint();
  ckpt.architecture = "conv(3,3)";
  SaveCheckpoint(path_, ckpt);
  const std::string error = LoadError();
  EXPECT_NE(error.find("invalid architecture"), std::string::npos) << error;
}

TEST_F(CheckpointTest, ConvNetWithBatchNormRoundTripsIncludingRunningStatistics) {
  std::mt19937 rng(23);
  Sequential net = MakeGraspCnn(5, &rng);
  Matrix x = Matrix::Random(net.InputSize(), 6).cwiseAbs();
  for (int i = 0; i < 3; ++i) net.Forward(x);
  Checkpoint ckpt;
  ckpt.architecture = net.Architecture();
  net.GetFlat(&ckpt.params);
  SaveCheckpoint(path_, ckpt);

  const Checkpoint loaded = LoadCheckpoint(path_);
  ASSERT_EQ(loaded.params.size(), static_cast<size_t>(net.FlatSize()));
  Sequential restored = BuildFromArchitecture(loaded.architecture, &rng);
  restored.SetFlat(loaded.params.data(), loaded.params.size());
  net.set_training(false);
  restored.set_training(false);
  EXPECT_EQ(Matrix(restored.Forward(x)), Matrix(net.Forward(x)));
  EXPECT_EQ(*restored.Buffers()[3].value, *net.Buffers()[3].value);

  // A checkpoint of the parameters without the buffers does not fit the architecture.
  ckpt.params.resize(static_cast<size_t>(net.NumParams()));
  SaveCheckpoint(path_, ckpt);
  EXPECT_THROW(LoadCheckpoint(path_), std::runtime_error);
}

// The learner's names, and the folder's checkpoint files by update: not another name, a
// temporary file, the learner's state or a folder that has a checkpoint's name.
TEST_F(CheckpointTest, ListsTheLearnersCheckpointFilesByUpdate) {
  EXPECT_EQ(CheckpointFileName(7), "ckpt-000000007.bin");
  EXPECT_EQ(CheckpointFileName(1234567890), "ckpt-1234567890.bin");
  const Checkpoint ckpt = MakeCheckpoint();
  for (const char* name : {"ckpt-000000100.bin", "ckpt-000000020.bin", "ckpt-1234567890.bin",
                           "ckpt-000000030.bin.tmp.77", "ckpt-12a.bin", "ckpt-.bin",
                           "learner-state.bin", "model.ckpt"}) {
    SaveCheckpoint((dir_ / name).string(), ckpt);
  }
  fs::create_directory(dir_ / "ckpt-000000050.bin");
  EXPECT_EQ(CheckpointFilesIn(dir_.string()),
            (std::vector<std::string>{(dir_ / "ckpt-000000020.bin").string(),
                                      (dir_ / "ckpt-000000100.bin").string(),
                                      (dir_ / "ckpt-1234567890.bin").string()}));
  EXPECT_TRUE(CheckpointFilesIn((dir_ / "missing").string()).empty());
}

}  // namespace
}  // namespace rl::nn
