#include "common/atomic_file.h"

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>

#include <gtest/gtest.h>

#include "tests/common/read_file.h"
#include "tests/common/temp_dir.h"

namespace rl {
namespace {

namespace fs = std::filesystem;

class AtomicFileTest : public TempDirTest {};

TEST_F(AtomicFileTest, WritesReplacesAndLeavesNoTemporaryFile) {
  const std::string path = (dir_ / "a.bin").string();
  const std::string first("one\0two", 7);  // bytes, NUL included
  WriteFileAtomically(path, first);
  EXPECT_EQ(ReadFile(path), first);
  WriteFileAtomically(path, "replaced");
  EXPECT_EQ(ReadFile(path), "replaced");
  EXPECT_FALSE(fs::exists(TemporaryPathFor(path)));
  EXPECT_EQ(std::distance(fs::directory_iterator(dir_), fs::directory_iterator{}), 1);
}

TEST_F(AtomicFileTest, AFailedWriteNamesThePathAndTheReasonAndKeepsTheOldFile) {
  const std::string missing = (dir_ / "no_such_dir" / "c.bin").string();
  try {
    WriteFileAtomically(missing, "x", "checkpoint");
    FAIL() << "no error";
  } catch (const std::runtime_error& e) {
    const std::string what = e.what();
    EXPECT_EQ(what.rfind("cannot write checkpoint " + missing + ": create ", 0), 0u) << what;
    EXPECT_NE(what.find("No such file or directory"), std::string::npos) << what;
  }
  // Renaming over a directory fails: the temporary file is removed, the target untouched.
  const fs::path target = dir_ / "target";
  fs::create_directories(target / "inside");
  EXPECT_THROW(WriteFileAtomically(target.string(), "x"), std::runtime_error);
  EXPECT_FALSE(fs::exists(TemporaryPathFor(target.string())));
  EXPECT_TRUE(fs::is_directory(target / "inside"));
}

TEST_F(AtomicFileTest, RenameIntoPlaceCommitsAFileWrittenElsewhere) {
  const fs::path tmp = dir_ / "video.tmp";
  std::ofstream(tmp) << "frames";
  const std::string path = (dir_ / "video.webm").string();
  RenameIntoPlace(tmp.string(), path, "video");
  EXPECT_EQ(ReadFile(path), "frames");
  EXPECT_FALSE(fs::exists(tmp));
  EXPECT_THROW(RenameIntoPlace(tmp.string(), path, "video"), std::runtime_error);  // gone
}

TEST_F(AtomicFileTest, AStreamCommitsWholeOrLeavesTheOldFile) {
  const std::string path = (dir_ / "s.bin").string();
  WriteFileAtomically(path, "old");
  {
    AtomicFileStream out(path);
    ASSERT_TRUE(out.Open());
    EXPECT_STREQ(out.temporary_path(), TemporaryPathFor(path).c_str());
    ASSERT_TRUE(out.Write("new ", 4));
    ASSERT_TRUE(out.Write("bytes", 5));
    EXPECT_EQ(ReadFile(path), "old");  // not yet
    ASSERT_TRUE(out.Commit());
    EXPECT_EQ(out.bytes_written(), 9);
  }
  EXPECT_EQ(ReadFile(path), "new bytes");
  {
    // Abandoned: the temporary file goes, the file stays.
    AtomicFileStream out(path);
    ASSERT_TRUE(out.Open());
    ASSERT_TRUE(out.Write("partial", 7));
  }
  EXPECT_EQ(ReadFile(path), "new bytes");
  EXPECT_EQ(std::distance(fs::directory_iterator(dir_), fs::directory_iterator{}), 1);
  // A failure names the step, the file and the reason.
  const std::string missing = (dir_ / "no_such_dir" / "s.bin").string();
  AtomicFileStream bad(missing);
  EXPECT_FALSE(bad.Open());
  EXPECT_STREQ(bad.failed_step(), "create");
  const std::string what = bad.ErrorMessage("snapshot");
  EXPECT_EQ(what.rfind("cannot write snapshot " + missing + ": create " + missing + ".tmp.", 0), 0u)
      << what;
  EXPECT_NE(what.find("No such file or directory"), std::string::npos) << what;
}

TEST_F(AtomicFileTest, RemovesTheTemporaryFilesOfKilledWritersAndNothingElse) {
  const auto touch = [&](const std::string& name) { std::ofstream(dir_ / name) << "x"; };
  // What writers killed mid-write leave, in a folder with files that must stay.
  for (const char* name : {"ckpt-000000500.bin.tmp.4242", "learner-state.bin.tmp.4243",
                           "replay-snapshot.bin.tmp.17"}) {
    touch(name);
  }
  const std::string own = "index.html.tmp." + std::to_string(getpid());
  for (const std::string& name : {std::string("ckpt-000000500.bin"), std::string("a.tmp."),
                                  std::string("b.tmp.12x"), std::string("c.tmp.webm"), own}) {
    touch(name);
  }
  fs::create_directories(dir_ / "sub.tmp.99");
  EXPECT_EQ(RemoveStaleTemporaries(dir_.string(), "replay-snapshot.bin.tmp."), 1);
  EXPECT_FALSE(fs::exists(dir_ / "replay-snapshot.bin.tmp.17"));
  EXPECT_TRUE(fs::exists(dir_ / "learner-state.bin.tmp.4243"));
  EXPECT_EQ(RemoveStaleTemporaries(dir_.string()), 2);
  for (const std::string& kept :
       {std::string("ckpt-000000500.bin"), std::string("a.tmp."), std::string("b.tmp.12x"),
        std::string("c.tmp.webm"), own, std::string("sub.tmp.99")}) {
    EXPECT_TRUE(fs::exists(dir_ / kept)) << kept;
  }
  EXPECT_EQ(std::distance(fs::directory_iterator(dir_), fs::directory_iterator{}), 6);
  EXPECT_EQ(RemoveStaleTemporaries((dir_ / "missing").string()), 0);
}

}  // namespace
}  // namespace rl
