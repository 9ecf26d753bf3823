// The supervisor with real processes (/bin/sh scripts standing in for the run's programs).
#include "launch/supervisor.h"

#include <fcntl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <stdexcept>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "common/clock.h"
#include "launch/placement.h"
#include "launch/proc.h"
#include "launch/watchdog.h"
#include "tests/common/read_file.h"
#include "tests/common/temp_dir.h"

namespace rl::launch {
namespace {

namespace fs = std::filesystem;

class SupervisorTest : public ::testing::Test {
 protected:
  void SetUp() override {
    fs::create_directories(dir_ + "/logs");
    plan_.identity.run_dir = dir_;
    plan_.settings.limits.first_backoff = 0.1;
    plan_.settings.limits.ready_timeout = 10;
  }

  // A process running `script` with /bin/sh; ready when it prints "ROLE: ready".
  void AddShell(const std::string& role, const std::string& script) {
    PlannedProcess p;
    p.role = p.kind = role;
    p.argv = {"/bin/sh", "-c", script};
    p.log = dir_ + "/logs/" + role + ".log";
    p.ready = {Readiness::kLogLine, role + ": ready"};
    plan_.processes.push_back(p);
  }
  // The process whose exit ends the run (as the monitor's does).
  void AddEnder(const std::string& script) {
    AddShell("monitor", script);
    PlannedProcess& p = plan_.processes.back();
    p.ready = {Readiness::kAtStart, ""};
    p.restart = false;
    p.ends_run = true;
    p.shown = true;
  }

  // A process that, on SIGTERM, writes its last file in DIR/ROLE (writes_at_stop) atomically, a
  // line every 0.1 s for `seconds`, then renames it to last.bin and exits; or, `hangs`, starts the
  // file and then hangs.
  void AddStopWriter(const std::string& role, double seconds, bool hangs) {
    const std::string folder = dir_ + "/" + role;
    fs::create_directories(folder);
    const std::string tmp = folder + "/last.bin.tmp.$$";
    const std::string on_term = hangs ? "echo x > " + tmp + "; while :; do sleep 0.1; done"
                                      : "for i in $(seq " +
                                            std::to_string(static_cast<int>(seconds * 10)) +
                                            "); do echo x >> " + tmp + "; sleep 0.1; done; mv " +
                                            tmp + " " + folder + "/last.bin; exit 0";
    AddShell(role,
             "trap '" + on_term + "' TERM; echo " + role + ": ready; while :; do sleep 0.1; done");
    plan_.processes.back().writes_at_stop = folder;
  }

  // A writer that writes its last file for `seconds` after SIGTERM and one that starts its file
  // and hangs, with stops that wait for a file until it has not changed for 2 s.
  void AddWriterAndHung(double seconds) {
    plan_.settings.limits.stop_stall_seconds = 2;
    AddStopWriter("writer", seconds, /*hangs=*/false);
    AddStopWriter("hung", 0, /*hangs=*/true);
  }

  // Runs the supervisor in this process with its output in files; returns how the run ended.
  RunEnd RunHere(double* seconds) {
    const int saved_out = dup(STDOUT_FILENO), saved_err = dup(STDERR_FILENO);
    const int out = open((dir_ + "/out").c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    const int err = open((dir_ + "/err").c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    dup2(out, STDOUT_FILENO);
    dup2(err, STDERR_FILENO);
    const double start = MonoSeconds();
    RunEnd end;
    {
      const int signal_fd = BlockRunSignals();
      Supervisor supervisor(plan_, placement_, signal_fd, nullptr);
      end = supervisor.Run();
      close(signal_fd);
    }
    *seconds = MonoSeconds() - start;
    dup2(saved_out, STDOUT_FILENO);
    dup2(saved_err, STDERR_FILENO);
    for (int fd : {saved_out, saved_err, out, err}) close(fd);
    return end;
  }

  // Starts the supervisor (and a watchdog of `grace` seconds) in a child process, the launcher;
  // returns its pid once every process of the plan has started.
  pid_t LaunchInChild(double grace) {
    const pid_t child = fork();
    if (child == 0) {
      const int null = open("/dev/null", O_WRONLY);
      dup2(null, STDOUT_FILENO);
      dup2(null, STDERR_FILENO);
      const int signal_fd = BlockRunSignals();
      RestartLimits limits = plan_.settings.limits;
      limits.stop_seconds = grace;
      Watchdog watchdog(limits);
      Supervisor supervisor(plan_, placement_, signal_fd, &watchdog);
      _exit(ExitStatusOf(supervisor.Run()));
    }
    const double deadline = MonoSeconds() + 20;
    while (ReadFile(dir_ + "/pids").find("monitor ") == std::string::npos) {
      if (MonoSeconds() > deadline) ADD_FAILURE() << "the processes did not start";
      if (MonoSeconds() > deadline) break;
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    return child;
  }

  // The lines of RUN/pids: each start's role and pid.
  std::vector<std::pair<std::string, pid_t>> PidLines() {
    std::vector<std::pair<std::string, pid_t>> lines;
    std::istringstream in(ReadFile(dir_ + "/pids"));
    std::string role;
    pid_t pid;
    while (in >> role >> pid) lines.emplace_back(role, pid);
    return lines;
  }
  // The pid of each process in RUN/pids (the last start of each).
  std::map<std::string, pid_t> Pids() {
    std::map<std::string, pid_t> pids;
    for (const auto& [role, pid] : PidLines()) pids[role] = pid;
    return pids;
  }

  // Waits (bounded) until none of `pids` is a living process; returns whether they all ended.
  static bool AllEnd(const std::map<std::string, pid_t>& pids, double limit) {
    const double deadline = MonoSeconds() + limit;
    while (MonoSeconds() < deadline) {
      bool alive = false;
      for (const auto& [role, pid] : pids) alive |= ProcessStartTime(pid) != 0;
      if (!alive) return true;
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    return false;
  }

  TempDir temp_dir_;
  // The run folder.
  const std::string dir_ = temp_dir_.path().string();
  RunPlan plan_;
  LocalPlacement placement_;
};

TEST_F(SupervisorTest, AnEarlierLaunchsReadyLineDoesNotCountAndAStartupErrorStopsTheRun) {
  // The log of an earlier launch, which got ready then.
  std::ofstream(dir_ + "/logs/svc.log") << "svc: ready\nsvc: stopped\n";
  AddShell("svc", "sleep 0.5; echo 'svc: error: snapshot " + dir_ + "/s.bin is torn'; exit 2");
  AddEnder("exec sleep 60");
  double seconds = 0;
  EXPECT_EQ(RunHere(&seconds), RunEnd::kFailed);
  EXPECT_LT(seconds, 5);
  const std::string err = ReadFile(dir_ + "/err");
  EXPECT_NE(err.find("launch: svc failed at its start (status 2, "), std::string::npos) << err;
  EXPECT_NE(err.find("svc: error: snapshot " + dir_ + "/s.bin is torn"), std::string::npos) << err;
  EXPECT_EQ(err.find("svc: stopped"), std::string::npos) << "an earlier launch's line: " << err;
  EXPECT_EQ(ReadFile(dir_ + "/pids").find("monitor"), std::string::npos) << "started past it";
}

TEST_F(SupervisorTest, ACrashedProcessIsRestartedAndTheRestartSaysHowItDied) {
  // Its first start crashes before it is ready (a signal is never a startup failure).
  AddShell("svc", "if [ ! -e " + dir_ + "/crashed ]; then touch " + dir_ +
                      "/crashed; kill -SEGV $$; fi; echo svc: ready; exec sleep 60");
  AddEnder("echo 'monitor: goal reached'; sleep 1; exit 0");
  double seconds = 0;
  EXPECT_EQ(RunHere(&seconds), RunEnd::kGoalReached);
  const std::string restarts = ReadFile(dir_ + "/restarts");
  EXPECT_EQ(restarts.substr(restarts.find(' ')), " svc status 139 restart 1\n") << restarts;
  const std::string said = "launch: svc was killed by signal 11 (SIGSEGV) after ";
  EXPECT_NE(ReadFile(dir_ + "/err").find(said), std::string::npos) << ReadFile(dir_ + "/err");
  EXPECT_NE(ReadFile(dir_ + "/err").find("; restarting it in 0.1 s (restart 1 of 5)"),
            std::string::npos);
  EXPECT_NE(ReadFile(dir_ + "/logs/svc.log").find(said), std::string::npos);
  // Two starts of svc, one of the monitor, whose output is the launcher's and its log.
  std::vector<std::string> roles;
  for (const auto& [role, pid] : PidLines()) roles.push_back(role);
  EXPECT_EQ(roles, (std::vector<std::string>{"svc", "svc", "monitor"}));
  EXPECT_EQ(ReadFile(dir_ + "/out"), "monitor: goal reached\n");
  EXPECT_EQ(ReadFile(dir_ + "/logs/monitor.log"), "monitor: goal reached\n");
}

TEST_F(SupervisorTest, WhenTheLauncherIsKilledItsProcessesStopAndTheStuckOnesAreKilled) {
  // One that stops cleanly on SIGTERM (as every program of a run does), one that ignores it; one
  // that writes its last file for 4 s (the watchdog waits for it past its 1 s), one that starts
  // it and hangs (killed once it has not changed for 2 s).
  AddShell("polite", "trap 'echo stopped > " + dir_ +
                         "/polite.stopped; exit 0' TERM; "
                         "echo polite: ready; while :; do sleep 0.1; done");
  AddShell("stubborn", "trap '' TERM; echo stubborn: ready; exec sleep 60");
  AddWriterAndHung(/*seconds=*/4);
  AddEnder("exec sleep 60");
  const pid_t launcher = LaunchInChild(/*grace=*/1);
  const std::map<std::string, pid_t> pids = Pids();
  ASSERT_EQ(pids.size(), 5u);
  kill(launcher, SIGKILL);
  waitpid(launcher, nullptr, 0);
  EXPECT_TRUE(AllEnd(pids, 30)) << "a process outlived its launcher";
  EXPECT_TRUE(fs::exists(dir_ + "/polite.stopped")) << "no SIGTERM for a clean stop";
  EXPECT_TRUE(fs::exists(dir_ + "/writer/last.bin")) << "killed while it was writing";
  EXPECT_FALSE(fs::exists(dir_ + "/hung/last.bin"));
}

TEST_F(SupervisorTest, AStopWaitsForALastFileBeingWrittenAndKillsAWriterThatHangs) {
  plan_.settings.limits.stop_seconds = 1;
  AddWriterAndHung(/*seconds=*/4);
  AddEnder("echo 'monitor: goal reached'; sleep 0.5; exit 0");
  double seconds = 0;
  EXPECT_EQ(RunHere(&seconds), RunEnd::kGoalReached);
  EXPECT_TRUE(fs::exists(dir_ + "/writer/last.bin")) << "killed while it was writing";
  const std::string err = ReadFile(dir_ + "/err");
  EXPECT_NE(err.find("launch: writer is still writing (last.bin.tmp."), std::string::npos) << err;
  EXPECT_EQ(err.find("launch: writer did not stop"), std::string::npos) << err;
  // Its file stopped changing when it started it: killed once the stall had lasted.
  EXPECT_NE(err.find("launch: hung did not stop; killing it"), std::string::npos) << err;
  EXPECT_FALSE(fs::exists(dir_ + "/hung/last.bin"));
  EXPECT_GE(seconds, 4);
}

TEST_F(SupervisorTest, AnExceptionInTheLauncherStillWaitsForALastFileBeingWritten) {
  // The supervisor's destructor stops the run when the launcher throws (here: its ready
  // callback), with the same rule as an orderly stop.
  plan_.settings.limits.stop_seconds = 1;
  AddWriterAndHung(/*seconds=*/3);
  AddEnder("exec sleep 60");
  const int signal_fd = BlockRunSignals();
  const double start = MonoSeconds();
  {
    Supervisor supervisor(plan_, placement_, signal_fd, nullptr);
    supervisor.OnAllReady([] { throw std::runtime_error("the launcher failed"); });
    EXPECT_THROW(supervisor.Run(), std::runtime_error);
  }
  const double seconds = MonoSeconds() - start;
  close(signal_fd);
  EXPECT_TRUE(fs::exists(dir_ + "/writer/last.bin")) << "killed while it was writing";
  EXPECT_FALSE(fs::exists(dir_ + "/hung/last.bin"));
  EXPECT_GE(seconds, 3);
  EXPECT_LT(seconds, 30) << "the hung writer was not killed after its stall";
  EXPECT_TRUE(AllEnd(Pids(), 1)) << "a process outlived the supervisor";
}

TEST_F(SupervisorTest, AHangUpStopsTheRunInOrder) {
  AddShell("polite", "trap 'echo stopped > " + dir_ +
                         "/polite.stopped; exit 0' TERM; "
                         "echo polite: ready; while :; do sleep 0.1; done");
  AddEnder("exec sleep 60");
  const pid_t launcher = LaunchInChild(/*grace=*/10);
  const std::map<std::string, pid_t> pids = Pids();
  // As a terminal's hang-up reaches the processes: the launcher and its process group.
  kill(launcher, SIGHUP);
  for (const auto& [role, pid] : pids) kill(pid, SIGHUP);
  int status = 0;
  waitpid(launcher, &status, 0);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 129);
  EXPECT_TRUE(AllEnd(pids, 1));
  EXPECT_TRUE(fs::exists(dir_ + "/polite.stopped")) << "the hang-up killed it before its stop";
}

}  // namespace
}  // namespace rl::launch
