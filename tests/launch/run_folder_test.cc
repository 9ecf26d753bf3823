#include "launch/run_folder.h"

#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <set>
#include <string>

#include <gtest/gtest.h>

#include "launch/launch_options.h"
#include "launch/proc.h"
#include "tests/common/temp_dir.h"

namespace rl::launch {
namespace {

namespace fs = std::filesystem;

class RunFolderTest : public TempDirTest {};

TEST_F(RunFolderTest, ADefaultNameThatIsTakenGetsASuffix) {
  const std::string wanted = (dir_ / "runs" / "cartpole-20261122-101500").string();
  EXPECT_EQ(CreateRunFolder(wanted, true), wanted);  // parents made too
  EXPECT_EQ(CreateRunFolder(wanted, true), wanted + "-2");
  EXPECT_EQ(CreateRunFolder(wanted, true), wanted + "-3");
}

TEST_F(RunFolderTest, LaunchesAtTheSameMomentGetFoldersOfTheirOwn) {
  const std::string wanted = (dir_ / "cartpole-20261122-101500").string();
  constexpr int kLaunches = 8;
  int pipes[kLaunches][2];
  for (auto& p : pipes) ASSERT_EQ(pipe(p), 0);
  for (int i = 0; i < kLaunches; ++i) {
    if (fork() == 0) {
      std::string got;
      try {
        got = CreateRunFolder(wanted, true);
      } catch (const std::exception& e) {
        got = std::string("error ") + e.what();
      }
      (void)!write(pipes[i][1], got.data(), got.size());
      _exit(0);
    }
  }
  std::set<std::string> folders;
  for (auto& p : pipes) {
    close(p[1]);
    char buf[4096];
    const ssize_t n = read(p[0], buf, sizeof(buf));
    close(p[0]);
    folders.insert(std::string(buf, n > 0 ? static_cast<size_t>(n) : 0));
  }
  while (wait(nullptr) > 0) {
  }
  EXPECT_EQ(folders.size(), static_cast<size_t>(kLaunches));
  for (const std::string& f : folders) EXPECT_TRUE(fs::is_directory(f)) << f;
}

TEST_F(RunFolderTest, AGivenFolderMustBeNewOrEmpty) {
  const std::string given = (dir_ / "mine").string();
  fs::create_directories(given);
  EXPECT_EQ(CreateRunFolder(given, false), given);  // empty: taken as it is
  std::ofstream(given + "/config.ini") << "x";
  try {
    CreateRunFolder(given, false);
    FAIL() << "no error";
  } catch (const LaunchError& e) {
    EXPECT_EQ(std::string(e.what()), "the run folder " + given +
                                         " exists and is not empty (pick another --out, or "
                                         "continue its run with --resume " +
                                         given + ")");
  }
}

TEST_F(RunFolderTest, AFolderThatCannotBeMadeIsOneClearLine) {
  std::ofstream(dir_ / "file") << "x";
  const std::string bad = (dir_ / "file" / "run").string();
  try {
    CreateRunFolder(bad, false);
    FAIL() << "no error";
  } catch (const LaunchError& e) {
    EXPECT_EQ(std::string(e.what()), "cannot create the run folder " + bad + ": Not a directory");
  }
}

TEST_F(RunFolderTest, OneLauncherPerRunFolder) {
  const std::string dir = dir_.string();
  std::ofstream(dir + "/launch.pid") << getpid() << " " << ProcessStartTime(getpid()) << "\n";
  {
    RunLock first(dir);
    try {
      RunLock second(dir);
      FAIL() << "a second lock was granted";
    } catch (const LaunchError& e) {
      EXPECT_EQ(std::string(e.what()),
                "the run in " + dir + " is going (launcher pid " + std::to_string(getpid()) +
                    "): stop it with scripts/launch.sh --stop " + dir + " first");
    }
  }
  RunLock again(dir);  // released with the first
}

TEST_F(RunFolderTest, LaunchPidNamesALivingLauncherOnly) {
  const std::string dir = dir_.string();
  EXPECT_FALSE(RunningLauncher(dir));  // no file
  WriteLaunchPid(dir);
  EXPECT_EQ(RunningLauncher(dir), getpid());
  // The same pid with another start time: a process that reused the pid.
  std::ofstream(dir + "/launch.pid") << getpid() << " 1\n";
  EXPECT_FALSE(RunningLauncher(dir));
  std::ofstream(dir + "/launch.pid") << "garbage\n";
  EXPECT_FALSE(RunningLauncher(dir));
}

TEST_F(RunFolderTest, TheHeaderReadsBackAsWritten) {
  RunHeader h;
  h.preset = "cartpole";
  h.started = "2026-11-22T10:15:00+01:00";
  h.run_id = 123456789;
  h.lcm_url = "udpm://239.255.76.67:23456?ttl=0&recv_buf_size=4194304";
  h.lcm_bulk_url = "udpm://239.255.76.67:23457?ttl=0&recv_buf_size=4194304";
  h.lcm_samples_url = "udpm://239.255.76.67:23458?ttl=0&recv_buf_size=4194304";
  h.actors = 2;
  h.num_actors = 6;
  h.seed = 4;
  h.goal = "-250";
  h.time_budget = 90.5;
  h.extra = "actor [--stats-hz 2] replay [] learner [] evaluator []";
  const std::string text = FormatRunHeader(h);
  EXPECT_EQ(text,
            "# Run of preset 'cartpole', started 2026-11-22T10:15:00+01:00\n"
            "# run-id = 123456789\n"
            "# lcm-url = udpm://239.255.76.67:23456?ttl=0&recv_buf_size=4194304\n"
            "# lcm-bulk-url = udpm://239.255.76.67:23457?ttl=0&recv_buf_size=4194304\n"
            "# lcm-samples-url = udpm://239.255.76.67:23458?ttl=0&recv_buf_size=4194304\n"
            "# actors = 2 (of 6), seed = 4, goal = -250, time budget = 90.5 s\n"
            "# extra: actor [--stats-hz 2] replay [] learner [] evaluator []\n");
  const RunHeader back = ParseRunHeader(
      text + "\nenv = CartPole-v1\n# resumed x: actors = 3, time budget = 9 s\n", "config.ini");
  EXPECT_EQ(back.preset, h.preset);
  EXPECT_EQ(back.run_id, h.run_id);
  EXPECT_EQ(back.Port(), 23456);
  EXPECT_EQ(back.lcm_bulk_url, h.lcm_bulk_url);
  EXPECT_EQ(back.lcm_samples_url, h.lcm_samples_url);
  EXPECT_EQ(back.actors, 2);
  EXPECT_EQ(back.num_actors, 6);
  EXPECT_EQ(back.seed, 4u);
  EXPECT_EQ(back.goal, "-250");
  EXPECT_EQ(back.extra, h.extra);
  EXPECT_THROW(ParseRunHeader("env = CartPole-v1\n", "config.ini"), LaunchError);
  // A run of an earlier version has no samples port in its header: it resumes all the same (the
  // plan gives it port + 2).
  std::string earlier = text;
  earlier.erase(earlier.find("# lcm-samples-url"),
                earlier.find("# actors") - earlier.find("# lcm-samples-url"));
  const RunHeader old = ParseRunHeader(earlier, "config.ini");
  EXPECT_EQ(old.Port(), 23456);
  EXPECT_EQ(old.lcm_samples_url, "");
  EXPECT_EQ(old.actors, 2);
}

TEST_F(RunFolderTest, TheKeyIsPrivateAndKept) {
  const std::string key = (dir_ / "key").string();
  EnsureKeyFile(key);
  struct stat st {};
  ASSERT_EQ(stat(key.c_str(), &st), 0);
  EXPECT_EQ(st.st_mode & 0777, 0600u);
  EXPECT_EQ(st.st_size, 32);
  std::ifstream in(key, std::ios::binary);
  const std::string first((std::istreambuf_iterator<char>(in)), {});
  EnsureKeyFile(key);  // a resumed run keeps its key
  std::ifstream again(key, std::ios::binary);
  EXPECT_EQ(std::string((std::istreambuf_iterator<char>(again)), {}), first);
}

}  // namespace
}  // namespace rl::launch
