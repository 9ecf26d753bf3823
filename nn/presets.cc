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

// The fully connected part: `hidden` units, then the Q values.
std::string Head(int in, int num_actions, bool dueling, int hidden = 512) {
  const std::string a = std::to_string(num_actions);
  const std::string i = std::to_string(in);
  const std::string h = std::to_string(hidden);
  return dueling ? "dueling(" + i + "," + h + "," + a + ")"
                 : "linear(" + i + "," + h + "),relu,linear(" + h + "," + a + ")";
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

std::string Grasp48CnnArchitecture(int num_actions, int in_channels, bool dueling) {
  RequirePositive(num_actions, "Grasp48Cnn: num_actions");
  RequirePositive(in_channels, "Grasp48Cnn: in_channels");
  return "conv2d(" + std::to_string(in_channels) +
         ",16,5,2,2,48,48),relu,conv2d(16,32,3,2,1,24,24),relu,conv2d(32,32,3,2,1,12,12),relu,"
         "flatten," +
         Head(32 * 6 * 6, num_actions, dueling, 256);
}

Sequential MakeGrasp48Cnn(int num_actions, std::mt19937* rng, int in_channels, bool dueling) {
  return BuildFromArchitecture(Grasp48CnnArchitecture(num_actions, in_channels, dueling), rng);
}

}  // namespace rl::nn
