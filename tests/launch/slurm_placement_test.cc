#include "launch/slurm_placement.h"

#include <csignal>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "launch/launch_options.h"
#include "launch/preset.h"
#include "launch/run_plan.h"

namespace rl::launch {
namespace {

TEST(SlurmPlacementTest, CpusPerNodeAreReadAsSlurmWritesThem) {
  EXPECT_EQ(ParseCpusPerNode("8(x2),4", 3), (std::vector<int>{8, 8, 4}));
  EXPECT_EQ(ParseCpusPerNode("7,1(x2)", 3), (std::vector<int>{7, 1, 1}));
  EXPECT_EQ(ParseCpusPerNode("1", 1), (std::vector<int>{1}));
  for (const char* bad : {"", "x", "8(x2", "8(x0)", "0", "4,,4", "8(x2),4 "}) {
    EXPECT_THROW(ParseCpusPerNode(bad, 3), LaunchError) << bad;
  }
  EXPECT_THROW(ParseCpusPerNode("8(x2)", 3), LaunchError);  // another count of nodes
}

TEST(SlurmPlacementTest, ActorsTakeTheCoresLeftOnEachNode) {
  EXPECT_EQ(ActorsPerNode({8, 8, 4}, std::nullopt), (std::vector<int>{5, 8, 4}));
  EXPECT_EQ(ActorsPerNode({3, 2}, std::nullopt), (std::vector<int>{0, 2}));
  EXPECT_EQ(ActorsPerNode({5, 5}, 2), (std::vector<int>{2, 2}));
}

TEST(SlurmPlacementTest, TooFewCoresAreRefusedWithWhatToAskFor) {
  try {
    ActorsPerNode({1, 1}, std::nullopt);
    FAIL() << "no error";
  } catch (const LaunchError& e) {
    EXPECT_NE(std::string(e.what()).find("1 core on its first node, which needs 3"),
              std::string::npos)
        << e.what();
    EXPECT_NE(std::string(e.what()).find("--exclusive"), std::string::npos) << e.what();
  }
  EXPECT_THROW(ActorsPerNode({3}, std::nullopt), LaunchError);  // no actor left
  EXPECT_THROW(ActorsPerNode({4, 4}, 2), LaunchError);          // 3 + 2 on the first
  EXPECT_THROW(ActorsPerNode({8, 1}, 2), LaunchError);          // 2 on the second
  EXPECT_THROW(ActorsPerNode({8, 8}, 0), LaunchError);          // none at all
}

SlurmPlacement TwoNodes() {
  return SlurmPlacement({"42", {"node1", "node2"}, {5, 4}, "198.18.1.11"}, {2, 4});
}

TEST(SlurmPlacementTest, StepsGoToTheirNodesAndTheRestStaysBesideTheLauncher) {
  const SlurmPlacement placement = TwoNodes();
  EXPECT_EQ(placement.TotalActors(), 6);
  LaunchOptions o = ParseLaunchArgs({"cartpole", "--slurm", "--transport", "tcp"});
  const Preset preset = Preset::Parse("[evaluator]\ngoal = 475\n", "/c/cartpole.ini");
  RunSettings s = ResolveSettings(o, preset, nullptr, "/bin");
  s.actors = s.num_actors = placement.TotalActors();
  s.hub_host = "198.18.1.11";
  const RunPlan plan = BuildRunPlan(s, {"/runs/r", 7, 23456});
  EXPECT_EQ(plan.lcm_url, "tcpq://198.18.1.11:23456");
  EXPECT_EQ(plan.lcm_bulk_url, "tcpq://198.18.1.11:23457");
  // Through the hubs the sample replies share the bulk hub, which forwards them to the learner
  // alone.
  EXPECT_EQ(plan.lcm_samples_url, plan.lcm_bulk_url);
  std::vector<std::string> nodes;
  for (const PlannedProcess& p : plan.processes) {
    const std::vector<std::string> c = placement.Command(p);
    if (c[0] != "srun") {
      EXPECT_TRUE(p.kind == "hub" || p.kind == "monitor") << p.role;
      EXPECT_EQ(c, p.argv);
      EXPECT_EQ(placement.StopSignal(p), SIGTERM);
      continue;
    }
    EXPECT_EQ(placement.StopSignal(p), SIGUSR2) << p.role;
    EXPECT_EQ(std::vector<std::string>(c.end() - static_cast<long>(p.argv.size()), c.end()),
              p.argv);
    for (const std::string& w : c) {
      if (w.rfind("--nodelist=", 0) == 0) nodes.push_back(p.role + "@" + w.substr(11));
    }
  }
  EXPECT_EQ(nodes, (std::vector<std::string>{"replay@node1", "learner@node1", "evaluator@node1",
                                             "actor-0@node1", "actor-1@node1", "actor-2@node2",
                                             "actor-3@node2", "actor-4@node2", "actor-5@node2"}));
  EXPECT_EQ(plan.processes[0].role, "hub");
  EXPECT_EQ(plan.processes[1].role, "hub-bulk");
  EXPECT_TRUE(plan.processes[0].stops_last);
  EXPECT_EQ(plan.processes[1].ready.kind, Readiness::kListens);
  EXPECT_EQ(plan.processes[1].ready.text, "23457");
}

TEST(SlurmPlacementTest, TheTransportIsUdpmOrTcpAndTheSlurmOptionsNeedSlurm) {
  EXPECT_THROW(ParseLaunchArgs({"cartpole", "--slurm", "--transport", "udp"}), LaunchError);
  EXPECT_THROW(ParseLaunchArgs({"cartpole", "--transport", "tcp"}), LaunchError);
  EXPECT_THROW(ParseLaunchArgs({"cartpole", "--actors-per-node", "2"}), LaunchError);
  EXPECT_THROW(ParseLaunchArgs({"cartpole", "--slurm", "--actors", "2"}), LaunchError);
  EXPECT_THROW(ParseLaunchArgs({"cartpole", "--or-resume"}), LaunchError);
  const LaunchOptions o = ParseLaunchArgs({"cartpole", "--slurm", "--out", "r", "--or-resume"});
  EXPECT_TRUE(o.slurm && o.or_resume);
  EXPECT_EQ(o.transport, "udpm");
}

}  // namespace
}  // namespace rl::launch
