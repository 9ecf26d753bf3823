#include "nn/presets.h"

#include <stdexcept>
#include <string>

#include "nn/activations.h"

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

namespace {

// linear(in,h1),relu,...,linear(hk,out): the layers of an MLP as an architecture string.
std::string MlpLayers(int in, const std::vector<int>& hidden, int out) {
  RequirePositive(in, "Td3Mlp: input size");
  RequirePositive(out, "Td3Mlp: output size");
  std::string arch;
  for (int h : hidden) {
    RequirePositive(h, "Td3Mlp: hidden width");
    arch += "linear(" + std::to_string(in) + "," + std::to_string(h) + "),relu,";
    in = h;
  }
  return arch + "linear(" + std::to_string(in) + "," + std::to_string(out) + ")";
}

}  // namespace

std::string Td3MlpActorArchitecture(int obs_size, const std::vector<int>& hidden,
                                    const std::vector<float>& low, const std::vector<float>& high) {
  const int actions = static_cast<int>(low.size());
  if (actions < 1 || high.size() != low.size()) {
    throw std::invalid_argument("Td3MlpActor: needs one low and one high bound per action");
  }
  const Bounded bounds(low, high);  // checks the bounds and writes them exactly
  return MlpLayers(obs_size, hidden, actions) + "," + bounds.Describe();
}

std::string Td3MlpCriticArchitecture(int obs_size, int action_size,
                                     const std::vector<int>& hidden) {
  RequirePositive(action_size, "Td3MlpCritic: action size");
  return "||" + MlpLayers(obs_size + action_size, hidden, 1);
}

std::string CarEncoderArchitecture() {
  return "conv2d(4,16,4,2,0,84,84),relu,maxpool2d(16,2,41,41),conv2d(16,32,4,2,0,20,20),relu,"
         "avgpool2d(32,2,9,9),flatten";
}

std::string Td3CarActorArchitecture(const std::vector<float>& low, const std::vector<float>& high) {
  const int actions = static_cast<int>(low.size());
  if (actions < 1 || high.size() != low.size()) {
    throw std::invalid_argument("Td3CarActor: needs one low and one high bound per action");
  }
  const Bounded bounds(low, high);
  const std::string a = std::to_string(actions);
  return CarEncoderArchitecture() + ",layernorm(512),linear(512,128),relu,linear(128," + a +
         "),layernorm(" + a + ")," + bounds.Describe();
}

std::string DrqActorHeadArchitecture(int hidden, const std::vector<float>& low,
                                     const std::vector<float>& high) {
  const int actions = static_cast<int>(low.size());
  if (hidden < 1 || actions < 1 || high.size() != low.size()) {
    throw std::invalid_argument("DrqActorHead: needs hidden >= 1 and one bound pair per action");
  }
  const Bounded bounds(low, high);
  const std::string h = std::to_string(hidden);
  return "linear(512,50),layernorm(50),tanh,linear(50," + h + "),relu,linear(" + h + "," + h +
         "),relu,linear(" + h + "," + std::to_string(actions) + ")," + bounds.Describe();
}

std::string DrqCriticHeadArchitecture(int hidden, int action_size) {
  if (hidden < 1 || action_size < 1) {
    throw std::invalid_argument("DrqCriticHead: needs hidden >= 1 and action_size >= 1");
  }
  const std::string h = std::to_string(hidden);
  return "linear(512,50),layernorm(50),tanh||linear(" + std::to_string(50 + action_size) + "," + h +
         "),relu,linear(" + h + "," + h + "),relu,linear(" + h + ",1)";
}

std::string Td3CarCriticArchitecture() {
  return CarEncoderArchitecture() + ",linear(512,128),relu,linear(128,3),relu|linear(3,3),relu|" +
         "linear(6,3),relu,linear(3,1)";
}

}  // namespace rl::nn
