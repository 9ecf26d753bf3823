#include "learner/parameter_average.h"

#include <stdexcept>
#include <vector>

#include <gtest/gtest.h>

#include "common/state_file.h"

namespace rl::learner {
namespace {

TEST(ParameterAverageTest, IsThePlainMeanUpToItsHorizonThenAnExponentialAverage) {
  ParameterAverage average(3);
  EXPECT_TRUE(average.values().empty());
  average.Add(std::vector<float>{3.0f, -6.0f});
  EXPECT_EQ(average.values(), (std::vector<float>{3.0f, -6.0f}));
  average.Add(std::vector<float>{5.0f, 0.0f});
  EXPECT_EQ(average.values(), (std::vector<float>{4.0f, -3.0f}));
  average.Add(std::vector<float>{7.0f, 3.0f});
  EXPECT_FLOAT_EQ(average.values()[0], 5.0f);
  EXPECT_FLOAT_EQ(average.values()[1], -1.0f);
  EXPECT_EQ(average.count(), 3);
  // From here on each new vector weighs 1/3: 5 + (8 - 5) / 3 = 6, -1 + (-1 - -1) / 3 = -1.
  average.Add(std::vector<float>{8.0f, -1.0f});
  EXPECT_FLOAT_EQ(average.values()[0], 6.0f);
  EXPECT_FLOAT_EQ(average.values()[1], -1.0f);
  EXPECT_EQ(average.count(), 3);
}

TEST(ParameterAverageTest, AHorizonOfOneIsTheLastVector) {
  ParameterAverage average(1);
  average.Add(std::vector<float>{1.0f});
  average.Add(std::vector<float>{-2.5f});
  EXPECT_EQ(average.values(), std::vector<float>{-2.5f});
  EXPECT_THROW(ParameterAverage(0), std::invalid_argument);
}

TEST(ParameterAverageTest, AVectorOfAnotherLengthStartsAgain) {
  ParameterAverage average(4);
  average.Add(std::vector<float>{1.0f, 1.0f});
  average.Add(std::vector<float>{3.0f, 3.0f});
  average.Add(std::vector<float>{9.0f, 9.0f, 9.0f});
  EXPECT_EQ(average.values(), (std::vector<float>{9.0f, 9.0f, 9.0f}));
  EXPECT_EQ(average.count(), 1);
}

TEST(ParameterAverageTest, SavesAndLoadsThroughAStateFile) {
  ParameterAverage average(5);
  average.Add(std::vector<float>{2.0f, 4.0f});
  average.Add(std::vector<float>{4.0f, 8.0f});
  StateFile state("learner test");
  average.Save(&state, "avg");
  const StateFile read = StateFile::Parse(state.Serialize(), "learner test");

  ParameterAverage loaded(5);
  loaded.Load(read, "avg", 2);
  EXPECT_EQ(loaded.values(), average.values());
  EXPECT_EQ(loaded.count(), 2);
  // It goes on as the saved one would have.
  average.Add(std::vector<float>{0.0f, 0.0f});
  loaded.Add(std::vector<float>{0.0f, 0.0f});
  EXPECT_EQ(loaded.values(), average.values());

  // A saved average of another length is refused; a state without one leaves it empty.
  ParameterAverage other(5);
  EXPECT_THROW(other.Load(read, "avg", 3), std::runtime_error);
  ParameterAverage absent(5);
  absent.Load(StateFile("learner test"), "avg", 2);
  EXPECT_TRUE(absent.values().empty());
}

}  // namespace
}  // namespace rl::learner
