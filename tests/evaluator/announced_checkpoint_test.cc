// The checkpoint files an announcement can make the evaluator read: regular files of a bounded
// size in the run's checkpoint folder, nothing else, and never a blocking open or an endless read.
#include "evaluator/announced_checkpoint.h"

#include <sys/stat.h>

#include <filesystem>
#include <random>
#include <stdexcept>
#include <string>

#include <gtest/gtest.h>

#include "file_helpers.h"
#include "nn/checkpoint.h"
#include "nn/sequential.h"
#include "tests/common/temp_dir.h"

namespace rl::evaluator {
namespace {

namespace fs = std::filesystem;
using testing::FifoUnblocker;

nn::Checkpoint SmallCheckpoint(int64_t update) {
  std::mt19937 rng(3);
  const nn::Sequential net = nn::MakeMlp(4, {8}, 2, &rng);
  nn::Checkpoint ckpt;
  ckpt.architecture = net.Architecture();
  net.GetFlat(&ckpt.params);
  ckpt.meta.update = update;
  return ckpt;
}

// Why reading `announced` from `folder` is refused (empty when it is read).
std::string Refusal(const std::string& announced, const std::string& folder,
                    int64_t max_bytes = kMaxAnnouncedCheckpointBytes) {
  try {
    ReadAnnouncedCheckpoint(announced, folder, max_bytes);
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "";
}

class AnnouncedCheckpointTest : public ::testing::Test {
 protected:
  AnnouncedCheckpointTest() {
    fs::create_directories(folder_);
    nn::SaveCheckpoint(folder_ + "/ckpt-000000100.bin", SmallCheckpoint(100));
    nn::SaveCheckpoint(dir_ / "elsewhere.bin", SmallCheckpoint(7));
  }

  TempDir dir_;
  const std::string folder_ = dir_ / "run/checkpoints";
};

TEST_F(AnnouncedCheckpointTest, ReadsACheckpointOfTheFolderByAnyPathThatLeadsThere) {
  EXPECT_EQ(ReadAnnouncedCheckpoint(folder_ + "/ckpt-000000100.bin", folder_).meta.update, 100);
  // Through "..", or a folder given with a trailing slash: where the parent leads counts.
  EXPECT_EQ(Refusal(dir_ / "run/checkpoints/../checkpoints/ckpt-000000100.bin", folder_ + "/"), "");
  // Relative to the working directory, as a learner started in the run folder announces it.
  const fs::path cwd = fs::current_path();
  fs::current_path(dir_ / "run");
  EXPECT_EQ(Refusal("checkpoints/ckpt-000000100.bin", "checkpoints"), "");
  fs::current_path(cwd);
}

TEST_F(AnnouncedCheckpointTest, RefusesFilesOutsideTheFolderHoweverNamed) {
  for (const std::string& path :
       {(dir_ / "elsewhere.bin").string(), folder_ + "/../../elsewhere.bin",
        std::string("/dev/zero"), std::string("/proc/self/mem"), folder_ + "/../checkpoints",
        folder_ + "/.", folder_ + "/", std::string("ckpt-000000100.bin")}) {
    const std::string why = Refusal(path, folder_);
    EXPECT_FALSE(why.empty()) << path << " was read";
  }
  EXPECT_NE(Refusal("/dev/zero", folder_).find("not a file of the run's checkpoint folder"),
            std::string::npos);
  EXPECT_NE(Refusal(folder_ + "/ckpt-000000100.bin", "").find("no checkpoint folder"),
            std::string::npos);
}

TEST_F(AnnouncedCheckpointTest, RefusesSymbolicLinksInTheFolderEvenToGoodCheckpoints) {
  fs::create_symlink(dir_ / "elsewhere.bin", folder_ + "/ckpt-000000200.bin");
  fs::create_symlink("/dev/zero", folder_ + "/ckpt-000000300.bin");
  fs::create_symlink(folder_ + "/ckpt-000000100.bin", folder_ + "/ckpt-000000400.bin");
  for (const char* name : {"ckpt-000000200.bin", "ckpt-000000300.bin", "ckpt-000000400.bin"}) {
    EXPECT_NE(Refusal(folder_ + "/" + name, folder_).find("a symbolic link"), std::string::npos)
        << name;
  }
  // A link to another folder as the parent leads elsewhere.
  fs::create_directory_symlink(dir_.path(), folder_ + "/up");
  EXPECT_NE(Refusal(folder_ + "/up/elsewhere.bin", folder_).find("not a file of the run's"),
            std::string::npos);
}

// A FIFO would block a reading open until a writer comes: it is opened without blocking and
// refused. (Should the open block, a helper thread opens the FIFO for writing, so that the test
// fails on the reason instead of hanging.)
TEST_F(AnnouncedCheckpointTest, RefusesAFifoWithoutBlocking) {
  const std::string fifo = folder_ + "/ckpt-000000500.bin";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  std::string why;
  {
    const FifoUnblocker unblock(fifo);
    why = Refusal(fifo, folder_);
  }
  EXPECT_NE(why.find("not a regular file"), std::string::npos) << why;
}

TEST_F(AnnouncedCheckpointTest, RefusesAFileAboveTheSizeBound) {
  const std::string path = folder_ + "/ckpt-000000100.bin";
  const auto size = static_cast<int64_t>(fs::file_size(path));
  EXPECT_EQ(Refusal(path, folder_, size), "");
  EXPECT_NE(Refusal(path, folder_, size - 1).find("above the bound"), std::string::npos);
  // What the file holds is checked as nn::LoadCheckpoint checks it.
  fs::resize_file(path, static_cast<uintmax_t>(size - 3));
  EXPECT_NE(Refusal(path, folder_).find("truncated"), std::string::npos);
}

TEST_F(AnnouncedCheckpointTest, QuotesAPathWithControlCharactersHarmlessly) {
  const std::string why = Refusal(folder_ + "/\n\x1b[2Jckpt.bin", folder_);
  EXPECT_EQ(why.find('\n'), std::string::npos) << why;
  EXPECT_EQ(why.find('\x1b'), std::string::npos) << why;
  EXPECT_NE(why.find("??[2Jckpt.bin"), std::string::npos) << why;
}

}  // namespace
}  // namespace rl::evaluator
