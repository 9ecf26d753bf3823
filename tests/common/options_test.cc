#include "common/options.h"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "tests/common/error_of.h"
#include "tests/common/temp_dir.h"

namespace rl {
namespace {

namespace fs = std::filesystem;

// Parses `args` (after the program name) with --config set to an INI file of `ini`, for role
// "evaluator", and returns the env and episodes read.
struct Parsed {
  std::string env;
  int episodes = 0;
};
Parsed Parse(const std::string& ini, std::vector<std::string> args = {}) {
  const TempDir dir;
  const fs::path path = dir / "options.ini";
  std::ofstream(path) << ini;
  CommonOptions common;
  Parsed p;
  po::options_description desc("Options");
  AddCommonOptions(&desc, &common);
  desc.add_options()("env", po::value(&p.env)->default_value("CartPole-v1"), "env")  //
      ("episodes", po::value(&p.episodes)->default_value(100), "episodes");
  args.insert(args.begin(), {"evaluator", "--config", path.string()});
  std::vector<char*> argv;
  for (std::string& a : args) argv.push_back(a.data());
  po::variables_map vm;
  ParseOptions(static_cast<int>(argv.size()), argv.data(), "evaluator", "usage", desc, &vm);
  return p;
}

// The message of the error Parse(ini) throws, which must be a std::runtime_error.
std::string ParseError(const std::string& ini) {
  EXPECT_THROW(Parse(ini), std::runtime_error);
  return ErrorOf([&] { Parse(ini); });
}

TEST(OptionsTest, OnCommandLineTellsTheCommandLinesOptionsFromTheConfigFiles) {
  const TempDir dir;
  const fs::path path = dir / "options.ini";
  std::ofstream(path) << "[evaluator]\nensemble = 5\n";
  CommonOptions common;
  int ensemble = 1;
  int episodes = 100;
  po::options_description desc("Options");
  AddCommonOptions(&desc, &common);
  desc.add_options()("ensemble", po::value(&ensemble)->default_value(1), "ensemble")  //
      ("episodes", po::value(&episodes)->default_value(100), "episodes");
  std::vector<std::string> args = {"evaluator", "--config", path.string(), "--episodes=3"};
  std::vector<char*> argv;
  for (std::string& a : args) argv.push_back(a.data());
  const int argc = static_cast<int>(argv.size());
  po::variables_map vm;
  ASSERT_TRUE(ParseOptions(argc, argv.data(), "evaluator", "usage", desc, &vm));
  EXPECT_EQ(ensemble, 5);  // from the file
  EXPECT_FALSE(vm["ensemble"].defaulted());
  EXPECT_FALSE(OnCommandLine(argc, argv.data(), desc, "ensemble"));
  EXPECT_TRUE(OnCommandLine(argc, argv.data(), desc, "episodes"));
  args.emplace_back("--ensemble");
  args.emplace_back("2");
  argv.clear();
  for (std::string& a : args) argv.push_back(a.data());
  EXPECT_TRUE(OnCommandLine(static_cast<int>(argv.size()), argv.data(), desc, "ensemble"));
}

TEST(OptionsTest, TheSectionWinsOverTheTopLevelAndTheCommandLineOverBoth) {
  const std::string ini =
      "env = CarRacing-v3+pixels(skip=5,off-track=1)\nepisodes = 7\nunknown-top = 1\n"
      "[actor]\nepisodes = 3\n[evaluator]\nenv = CarRacing-v3+pixels(skip=5)\n";
  Parsed p = Parse(ini);
  EXPECT_EQ(p.env, "CarRacing-v3+pixels(skip=5)");  // the [evaluator] section's
  EXPECT_EQ(p.episodes, 7);                         // top level; [actor] is not ours
  p = Parse(ini, {"--env", "Pendulum-v1"});
  EXPECT_EQ(p.env, "Pendulum-v1");
  p = Parse("env = Pendulum-v1\n");
  EXPECT_EQ(p.env, "Pendulum-v1");
}

TEST(OptionsTest, AnUnknownKeyInOurSectionIsRefusedWithItsName) {
  const std::string error = ParseError("[evaluator]\nepsiodes = 3\n");
  EXPECT_NE(error.find("unknown key 'epsiodes' in section [evaluator]"), std::string::npos)
      << error;
}

TEST(OptionsTest, ASectionOfNoProcessIsRefusedWithItsName) {
  const std::string error = ParseError("env = CartPole-v1\n[lerner]\nlearning-rate = 0.001\n");
  EXPECT_NE(error.find("unknown section [lerner] (key 'learning-rate')"), std::string::npos)
      << error;
  // The other processes' sections are not ours, but no error.
  EXPECT_EQ(Parse("[replay]\ncapacity = 5\n[learner]\nx = 1\n").episodes, 100);
}

TEST(OptionsTest, ListOptionsPrintsTheNamesAPresetMaySet) {
  CommonOptions common;
  po::options_description desc("Options");
  AddCommonOptions(&desc, &common);
  desc.add_options()("episodes", po::value<int>(), "episodes");
  std::string program = "evaluator", flag = "--list-options";
  char* argv[] = {program.data(), flag.data()};
  po::variables_map vm;
  std::ostringstream out;
  std::streambuf* saved = std::cout.rdbuf(out.rdbuf());
  const bool go_on = ParseOptions(2, argv, "evaluator", "usage", desc, &vm);
  std::cout.rdbuf(saved);
  EXPECT_FALSE(go_on);
  EXPECT_EQ(out.str(),
            "run-id\nkey-file\nlcm-url\nlcm-bulk-url\nlcm-samples-url\nmax-message-age\nmax-clock-"
            "skew\nepisodes\n");
}

// The freshness window: seconds on the command line, microseconds in the bus's configuration;
// a window that is not positive (or beyond a day) is refused with the option's name.
TEST(OptionsTest, TheFreshnessWindowReachesTheBusAndABadOneIsRefused) {
  CommonOptions defaults;
  EXPECT_EQ(defaults.MakeBusConfig("actor-0").max_message_age, kDefaultMaxMessageAgeMicros);
  EXPECT_EQ(defaults.MakeBusConfig("actor-0").max_clock_skew, kDefaultMaxClockSkewMicros);
  po::options_description desc;
  CommonOptions common;
  AddCommonOptions(&desc, &common);
  const char* argv[] = {"x", "--max-message-age", "2.5", "--max-clock-skew", "0.5"};
  po::variables_map vm;
  ASSERT_TRUE(ParseOptions(5, const_cast<char**>(argv), "actor", "usage", desc, &vm));
  const BusConfig c = common.MakeBusConfig("actor-0");
  EXPECT_EQ(c.max_message_age, 2'500'000);
  EXPECT_EQ(c.max_clock_skew, 500'000);
  for (const double bad : {0.0, -1.0, 90000.0, std::nan("")}) {
    CommonOptions o;
    o.max_message_age = bad;
    try {
      o.MakeBusConfig("actor-0");
      ADD_FAILURE() << bad << " was taken";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find("--max-message-age"), std::string::npos);
    }
  }
}

}  // namespace
}  // namespace rl
