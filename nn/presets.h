// Ready-made convolutional Q networks for pixel observations (see nn/README.md).
#pragma once

#include <random>
#include <string>
#include <vector>

#include "nn/sequential.h"

namespace rl::nn {

/// The network of Mnih et al. 2015 ("Human-level control through deep reinforcement learning")
/// on stacks of four 84 x 84 frames (input 4 x 84 x 84 = 28224 features):
///   conv2d(4,32,8,4,0,84,84),relu,conv2d(32,64,4,2,0,20,20),relu,
///   conv2d(64,64,3,1,0,9,9),relu,flatten,linear(3136,512),relu,linear(512,num_actions)
/// With `dueling` the last two layers become dueling(3136,512,num_actions) (Wang et al. 2016).
/// Throws std::invalid_argument unless num_actions > 0.
std::string NatureCnnArchitecture(int num_actions, bool dueling = false);
/// BuildFromArchitecture(NatureCnnArchitecture(num_actions, dueling), rng). 1,687,719 parameters
/// for 7 actions.
Sequential MakeNatureCnn(int num_actions, std::mt19937* rng, bool dueling = false);

/// A smaller network for stacks of `in_channels` 40 x 40 grayscale frames (spatial sizes
/// 40 -> 9 -> 3 -> 1), with batch normalisation after the first two convolutions:
///   conv2d(C,32,8,4,0,40,40),batchnorm2d(32,9,9),relu,conv2d(32,64,4,2,0,9,9),
///   batchnorm2d(64,3,3),relu,conv2d(64,64,3,1,0,3,3),relu,flatten,linear(64,512),relu,
///   linear(512,num_actions)
/// With `dueling` the last two layers become dueling(64,512,num_actions). Throws
/// std::invalid_argument unless num_actions and in_channels are positive.
std::string GraspCnnArchitecture(int num_actions, int in_channels = 4, bool dueling = false);
/// BuildFromArchitecture(GraspCnnArchitecture(num_actions, in_channels, dueling), rng).
Sequential MakeGraspCnn(int num_actions, std::mt19937* rng, int in_channels = 4,
                        bool dueling = false);

/// A network for stacks of `in_channels` 48 x 48 grayscale frames at the KUKA camera's native
/// size, keeping where things are: three stride-2 convolutions (48 -> 24 -> 12 -> 6) and a 6 x 6
/// map into the head, no batch normalisation:
///   conv2d(C,16,5,2,2,48,48),relu,conv2d(16,32,3,2,1,24,24),relu,
///   conv2d(32,32,3,2,1,12,12),relu,flatten,linear(1152,256),relu,linear(256,num_actions)
/// With `dueling` the last two layers become dueling(1152,256,num_actions). The grasp network
/// above reduces 3-pixel objects through an 8 x 8 stride-4 layer to a 1 x 1 map. Throws
/// std::invalid_argument unless num_actions and in_channels are positive.
std::string Grasp48CnnArchitecture(int num_actions, int in_channels = 4, bool dueling = false);
/// BuildFromArchitecture(Grasp48CnnArchitecture(num_actions, in_channels, dueling), rng).
Sequential MakeGrasp48Cnn(int num_actions, std::mt19937* rng, int in_channels = 4,
                          bool dueling = false);

/// TD3 (Fujimoto et al. 2018), the author's networks for flat observations: the actor
///   linear(obs,h1),relu,...,linear(hk,actions),bounded(actions,low_1,high_1,...)
/// (a tanh scaled to the action box) and a critic (an ActionValueNet string, both branches empty)
///   ||linear(obs+actions,h1),relu,...,linear(hk,1)
/// Throws std::invalid_argument for non-positive sizes or bounds of another size than the action.
std::string Td3MlpActorArchitecture(int obs_size, const std::vector<int>& hidden,
                                    const std::vector<float>& low, const std::vector<float>& high);
std::string Td3MlpCriticArchitecture(int obs_size, int action_size, const std::vector<int>& hidden);

/// The TD3 CarRacing article's networks on 4 x 84 x 84 stacks (td3-carracing.md 1.2). Encoder:
///   conv2d(4,16,4,2,0,84,84),relu,maxpool2d(16,2,41,41),conv2d(16,32,4,2,0,20,20),relu,
///   avgpool2d(32,2,9,9),flatten  -> 512 features
/// Actor: encoder,layernorm(512),linear(512,128),relu,linear(128,a),layernorm(a),bounded(a,...).
/// Critic (ActionValueNet string): encoder,linear(512,128),relu,linear(128,3),relu | linear(3,3),
/// relu | linear(6,3),relu,linear(3,1), for 3-d actions (the article's).
std::string CarEncoderArchitecture();
/// DrQ-v2's heads (Yarats et al. 2021) on the car encoder's 512 features, for a TD3 whose encoder
/// is shared and trained by the critics only. Actor head:
///   linear(512,50),layernorm(50),tanh,linear(50,h),relu,linear(h,h),relu,linear(h,a),bounded(..)
/// Critic (ActionValueNet string on features): linear(512,50),layernorm(50),tanh||
///   linear(50+a,h),relu,linear(h,h),relu,linear(h,1)
/// Throws std::invalid_argument for hidden < 1 or mismatched bounds.
std::string DrqActorHeadArchitecture(int hidden, const std::vector<float>& low,
                                     const std::vector<float>& high);
std::string DrqCriticHeadArchitecture(int hidden, int action_size);
std::string Td3CarActorArchitecture(const std::vector<float>& low, const std::vector<float>& high);
std::string Td3CarCriticArchitecture();

}  // namespace rl::nn
