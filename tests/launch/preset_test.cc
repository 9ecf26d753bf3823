#include "launch/preset.h"

#include <string>

#include <gtest/gtest.h>

#include "launch/launch_options.h"

namespace rl::launch {
namespace {

// A small model of the processes' options, as `PROGRAM --list-options` prints them.
OptionNames Known() {
  return {{"actor", {"env", "gamma", "batch-size", "n-step"}},
          {"replay", {"env", "capacity", "min-size"}},
          {"learner", {"env", "learning-rate", "batch-size"}},
          {"evaluator", {"env", "gamma", "goal", "episodes"}}};
}

std::string CheckError(const std::string& text) {
  try {
    CheckPreset(Preset::Parse(text, "configs/x.ini"), Known());
  } catch (const LaunchError& e) {
    return e.what();
  }
  return "";
}

TEST(PresetTest, ReadsTopLevelAndSectionKeysWithInlineComments) {
  const Preset p = Preset::Parse(
      "# a comment\nenv = CartPole-v1\nactors = 2   # two of them\n\n[evaluator]\n"
      "goal = 475 # the env's threshold\n[learner]\nlearning-rate=0.001\n",
      "configs/x.ini");
  EXPECT_EQ(p.Find("", "env"), "CartPole-v1");
  EXPECT_EQ(p.Find("", "actors"), "2");
  EXPECT_EQ(p.Find("evaluator", "goal"), "475");
  EXPECT_EQ(p.Find("learner", "learning-rate"), "0.001");
  EXPECT_FALSE(p.Find("", "goal"));
  EXPECT_FALSE(p.Find("actor", "env"));
  EXPECT_EQ(CheckError("env = CartPole-v1\nactors = 2 # two\n[evaluator]\ngoal = 475 # g\n"), "");
}

TEST(PresetTest, AMisspelledSectionIsRefusedWithFileSectionAndKey) {
  EXPECT_EQ(CheckError("env = CartPole-v1\n[lerner]\nlearning-rate = 0.001\n"),
            "preset configs/x.ini: unknown section [lerner] (key 'learning-rate') (did you mean "
            "[learner]?); the sections are [actor], [replay], [learner] and [evaluator]");
}

TEST(PresetTest, AMisspelledKeyIsRefusedWithFileSectionAndKey) {
  EXPECT_EQ(CheckError("[learner]\nleraning-rate = 0.001\n"),
            "preset configs/x.ini: unknown key 'leraning-rate' in section [learner]: the learner "
            "has no such option (did you mean 'learning-rate'?)");
  EXPECT_EQ(CheckError("leraning-rate = 0.001\n"),
            "preset configs/x.ini: unknown top-level key 'leraning-rate': no process has that "
            "option (did you mean 'learning-rate'?)");
  // A key of another process's section is no key of this one's.
  EXPECT_EQ(CheckError("[replay]\nn-step = 3\n"),
            "preset configs/x.ini: unknown key 'n-step' in section [replay]: the replay has no "
            "such option");
}

TEST(PresetTest, TopLevelKeysOfAnyProcessAndTheLaunchersAreKnown) {
  EXPECT_EQ(CheckError("gamma = 0.99\ncapacity = 10\nactors = 3\n"), "");
}

TEST(PresetTest, ALineThatIsNoKeyValueIsRefusedWithTheFile) {
  try {
    Preset::Parse("env = CartPole-v1\njust words\n", "configs/x.ini");
    FAIL() << "no error";
  } catch (const LaunchError& e) {
    EXPECT_EQ(std::string(e.what()).rfind("preset configs/x.ini: ", 0), 0u) << e.what();
  }
}

}  // namespace
}  // namespace rl::launch
