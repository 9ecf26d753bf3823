// Actor: runs environments with an epsilon-greedy policy and publishes their transitions.
//
// Pixel envs (EnvSpec::frame_stack > 0) publish pixel_batch_t on RL_PIXEL_TRANSITIONS instead:
// every frame once, with an actor-local id, and transitions that name their stacks by frame id.
//
// It steps envs_per_actor environments in turn, acts with the newest complete weights version
// from the learner (uniformly at random until the first one arrives), turns steps into n-step
// transitions and publishes them in batches on RL_TRANSITIONS. While the replay's rate limiter
// says so (RL_FLOW), it pauses. It publishes stats_actor_t a few times per second.
//
// Single-threaded: the thread that calls Run() also handles LCM.
#pragma once

#include <cstdint>
#include <deque>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "actor/exploration.h"
#include "actor/nstep.h"
#include "actor/weights_assembler.h"
#include "common/lcm_bus.h"
#include "envs/env.h"
#include "nn/sequential.h"
#include "rlmsg/pixel_batch_t.hpp"
#include "rlmsg/transition_batch_t.hpp"

namespace rl::actor {

struct ActorConfig {
  std::string env_id = "CartPole-v1";  // registered environment id
  int actor_id = 0;                    // this actor's index, 0 .. num_actors - 1
  int num_actors = 1;                  // actors in the run (for the Ape-X epsilons)
  int envs_per_actor = 1;              // environments stepped in turn by this process
  uint64_t seed = 0;                   // run seed; env j is first reset with TrainingSeed(...)
  int batch_size = 64;                 // transitions per published message
  int n_step = 1;                      // n of the n-step returns
  double gamma = 0.99;                 // discount
  ExplorationConfig exploration;       // how epsilon is chosen
  double stats_hz = 4.0;               // stats messages per second
  int64_t max_steps = 0;               // stop after this many env steps (0: run until stopped)
  bool clip_rewards = false;           // clamp each step's reward to [-1, 1] in transitions

  // Throws std::invalid_argument naming the bad field.
  void Validate() const;
};

// Seed of the first reset of environment `env_index` of actor `actor_id`: distinct for every
// env of every actor of a run, and below 10^9, where the evaluator's seeds begin.
uint64_t TrainingSeed(uint64_t run_seed, int actor_id, int env_index);

class Actor {
 public:
  // Subscribes to weights and flow control on `bus`, which must outlive the actor.
  Actor(ActorConfig config, Bus* bus);
  Actor(const Actor&) = delete;
  Actor& operator=(const Actor&) = delete;

  // Acts, publishes and handles LCM until StopRequested() or max_steps.
  void Run();

  // Steps every environment once and publishes full batches. Returns the env steps taken.
  int StepEnvs();

  void PublishStats();

  int64_t env_steps() const { return env_steps_; }
  int64_t episodes() const { return episodes_; }
  int64_t weights_version() const { return weights_version_; }
  double epsilon() const { return epsilon_; }
  bool paused() const { return !insert_allowed_; }
  double mean_return() const;

 private:
  struct EnvSlot {
    std::unique_ptr<envs::Env> env;
    std::vector<float> obs;  // observation the next action is chosen from
    NStepAccumulator nstep;
    double episode_return = 0;
    int64_t episode_id = 0;
    // Pixel envs: ids of the frames of the current stack (oldest first), and their n-step
    // accumulator.
    std::vector<int64_t> stack_ids;
    std::vector<int64_t> next_stack_ids;
    FrameNStepAccumulator frame_nstep;
  };

  int SelectAction(const std::vector<float>& obs);
  void OnWeights(const rlmsg::weights_chunk_t& chunk);
  void Append(const Transition& t, int64_t episode_id);
  void PublishBatch();
  // Pixel envs: queues the env's newest frame and returns its id.
  int64_t AddFrame(const envs::Env& env);
  // Pixel envs: starts the stack of a freshly reset env.
  void StartStack(EnvSlot* s);
  void AppendPixels(const FrameTransition& t, int64_t episode_id);
  void PublishPixelBatch();

  ActorConfig config_;
  Bus* bus_;
  int obs_size_ = 0;
  int num_actions_ = 0;
  std::vector<EnvSlot> slots_;
  std::mt19937_64 rng_;
  std::uniform_real_distribution<double> unit_{0.0, 1.0};
  std::uniform_int_distribution<int> random_action_;

  nn::Sequential net_;
  WeightsAssembler assembler_;
  int64_t weights_version_ = -1;
  int64_t weights_refused_ = 0;

  bool insert_allowed_ = true;
  double epsilon_ = 1.0;
  bool annealed_ = false;  // epsilon changes with the step count (linear mode)
  int64_t env_steps_ = 0;
  int64_t episodes_ = 0;
  int64_t published_ = 0;
  std::deque<double> recent_returns_;  // last 100 episode returns
  rlmsg::transition_batch_t batch_{};
  bool pixels_ = false;  // the env gives frames (pixel_batch_t)
  int64_t next_frame_id_ = 0;
  rlmsg::pixel_batch_t pixel_batch_{};

  double stats_last_time_ = 0;
  int64_t stats_last_steps_ = 0;
};

}  // namespace rl::actor
