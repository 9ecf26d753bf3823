#include "nn/presets.h"

#include <stdexcept>
#include <string>

namespace rl::nn {
namespace {

void RequirePositive(int value, const char* what) {
  if (value <= 0) {
    throw std::invalid_argument(std::string(what) + " must be positive, got " +
                                std::to_string(value));
  }
}

// The fully connected part: hidden 512 units, then the Q values.
std::string Head(int in, int num_actions, bool dueling) {
  const std::string a = std::to_string(num_actions);
  const std::string i = std::to_string(in);
  return dueling ? "dueling(" + i + ",512," + a + ")"
                 : "linear(" + i + ",512),relu,linear(512," + a + ")";
}

}  // namespace

std::string NatureCnnArchitecture(int num_actions, bool dueling) {
  RequirePositive(num_actions, "NatureCnn: num_actions");
  return "conv2d(4,32,8,4,0,84,84),relu,conv2d(32,64,4,2,0,20,20),relu,"
         "conv2d(64,64,3,1,0,9,9),relu,flatten," +
         Head(3136, num_actions, dueling);
}

Sequential MakeNatureCnn(int num_actions, std::mt19937* rng, bool dueling) {
  return BuildFromArchitecture(NatureCnnArchitecture(num_actions, dueling), rng);
}

std::string GraspCnnArchitecture(int num_actions, int in_channels, bool dueling) {
  RequirePositive(num_actions, "GraspCnn: num_actions");
  RequirePositive(in_channels, "GraspCnn: in_channels");
  return "conv2d(" + std::to_string(in_channels) +
         ",32,8,4,0,40,40),batchnorm2d(32,9,9),relu,conv2d(32,64,4,2,0,9,9),batchnorm2d(64,3,3),"
         "relu,conv2d(64,64,3,1,0,3,3),relu,flatten," +
         Head(64, num_actions, dueling);
}

Sequential MakeGraspCnn(int num_actions, std::mt19937* rng, int in_channels, bool dueling) {
  return BuildFromArchitecture(GraspCnnArchitecture(num_actions, in_channels, dueling), rng);
}

}  // namespace rl::nn
