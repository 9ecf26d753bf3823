// Learner: samples batches from the replay daemon, trains an Algorithm (DQN or TD3, algorithm.h)
// on them, broadcasts the policy network's weights, writes and announces checkpoints, and
// publishes its stats. It learns the env's sizes from its static spec (envs/specs.h): it builds
// no env and links no physics or rendering.
//
// Sampling is request/reply with requests_in_flight requests outstanding; a request without a
// reply after request_timeout seconds is sent again with the same id (the replay ignores a
// request it already holds), so a lost reply stalls nothing. Single-threaded.
#pragma once

#include <cstdint>
#include <deque>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <tuple>

#include "common/clock.h"
#include "common/lcm_bus.h"
#include "envs/env.h"
#include "learner/algorithm.h"
#include "learner/algorithms.h"
#include "learner/batch_decoder.h"
#include "learner/parameter_average.h"
#include "learner/weights_publisher.h"
#include "rlmsg/priority_update_t.hpp"
#include "rlmsg/sample_batch_t.hpp"

namespace rl::learner {

struct LearnerConfig {
  std::string env_id = "CartPole-v1";  // environment (gives the network's input and output sizes)
  std::string algorithm = "dqn";       // the chosen algorithm's kName (learner/algorithms.h)
  AlgorithmConfigs algorithms;         // every algorithm's settings; the chosen one's are used
  // Pixel envs: shift every sampled observation by a random offset of up to this many pixels
  // (DrQ's random shift, Kostrikov et al. 2020; they use 4 on 84 x 84 frames). 0: none.
  int augment_shift = 0;
  uint64_t seed = 0;             // seed of the shifts (the algorithms have their own)
  int batch_size = 128;          // transitions per update
  int requests_in_flight = 4;    // sample requests outstanding at once
  double request_timeout = 2.0;  // seconds before a request is sent again
  int weights_every = 100;       // updates between weight broadcasts
  int checkpoint_every = 1000;   // updates between checkpoints
  int keep_checkpoints = 0;      // newest checkpoint files kept on disk, earlier lives' included
                                 // (0: all)
  bool prioritized = false;      // publish |TD errors| as priorities after every update
  // Checkpoints (what the evaluator scores) hold an exponential moving average of the policy's
  // parameters over about this many updates instead of its current ones; the actors still get
  // the current ones. 0: no average.
  int policy_average = 0;
  // The algorithm's learning rates fall linearly from their configured values at update 0 to
  // learning_rate_end times those at this update, and stay there (0: constant). Follows the
  // update count, so a resumed learner continues the schedule.
  int64_t learning_rate_decay_updates = 0;
  double learning_rate_end = 0.1;
  int threads = 1;  // compute threads of the network library (nn::SetNumThreads)
  // The networks' matrix products, "fp32" or "bf16" (nn/precision.h); kept in the learner state.
  // "auto": bf16 where the CPU runs bf16 products natively (nn::NativeBf16()), fp32 elsewhere,
  // and on a resume the precision the saved state was trained in. The Learner resolves it.
  std::string precision = "fp32";
  std::string out_dir = ".";  // checkpoints go to <out_dir>/checkpoints/
  // Continue from <out_dir>/checkpoints/learner-state.bin when it exists (written with every
  // checkpoint): networks, targets, optimizers, counters, generators, env steps and wall time.
  bool resume = false;
  int64_t max_updates = 0;  // stop after this many updates (0: until stopped)
  double stats_hz = 4.0;    // stats messages per second

  void Validate() const;

  template <class Config>
  Config& Get() {
    return std::get<Config>(algorithms);
  }
  template <class Config>
  const Config& Get() const {
    return std::get<Config>(algorithms);
  }
};

/// The learning rates' scale for the update after `updates` updates under that decay: 1 at 0,
/// `end` from `decay_updates` on, linear between; 1 throughout when decay_updates is 0.
float LearningRateScale(int64_t updates, int64_t decay_updates, double end);

class Learner {
 public:
  // Subscribes to sample replies on `bus`, which must outlive the learner.
  Learner(LearnerConfig config, Bus* bus);
  Learner(const Learner&) = delete;
  Learner& operator=(const Learner&) = delete;

  // Trains until StopRequested() or max_updates, then writes a last checkpoint.
  void Run();

  int64_t updates() const { return algorithm_->updates(); }
  Algorithm& algorithm() { return *algorithm_; }
  const envs::EnvSpec& spec() const { return spec_; }
  // Sample replies that did not fit the networks (counted, dropped, logged).
  int64_t batches_refused() const { return batches_refused_; }
  // Writes a checkpoint of the current parameters and the learner's whole state
  // (StatePath()), announces the checkpoint and returns its path.
  std::string Checkpoint();
  // Where the state a restarted learner resumes from is written.
  std::string StatePath() const;
  // Whether the constructor resumed from a saved state.
  bool resumed() const { return resumed_; }
  // The networks' precision, "fp32" or "bf16" ("auto" resolved).
  const std::string& precision() const { return config_.precision; }

 private:
  struct Request {
    double sent = 0;
  };

  // Takes a reply if it answers one of our requests in flight; false for another learner's or a
  // duplicate.
  bool Accept(const std::string& requester, int64_t request_id, int64_t total_inserts);
  void OnSamples(rlmsg::sample_batch_t& m);
  void PublishPriorities(const std::vector<int64_t>& index);
  void TopUpRequests(double now);
  void SendRequest(int64_t id);
  void TrainOn(const rlmsg::sample_batch_t& batch);
  void PublishStats(double now);
  // The learner's whole state, and its inverse (throws std::runtime_error saying what is wrong).
  StateFile SaveState() const;
  void LoadState(const StateFile& state);
  std::string StateKind() const;
  static std::string StateKind(const LearnerConfig& c);
  static std::string StatePath(const LearnerConfig& c);
  // `c` validated, with precision "auto" resolved (LearnerConfig::precision).
  static LearnerConfig Resolved(LearnerConfig c);

  LearnerConfig config_;
  Bus* bus_;
  envs::EnvSpec spec_;
  std::unique_ptr<Algorithm> algorithm_;
  BatchDecoder decoder_;
  WeightsPublisher weights_;
  std::string sender_;
  double start_time_ = 0;
  double resumed_wall_seconds_ = 0;  // training time before this process started
  bool resumed_ = false;

  std::map<int64_t, Request> in_flight_;  // by request id
  int64_t next_request_id_ = 0;
  std::deque<rlmsg::sample_batch_t> ready_;
  // Batches trained on, kept for their arrays: a reply is swapped into one of them rather than
  // copied (megabytes of pixels per update in a pixel run), and the subscription decodes the
  // next reply into the arrays it got back.
  std::vector<rlmsg::sample_batch_t> spare_;
  int64_t batches_refused_ = 0;
  rlmsg::priority_update_t priorities_{};
  int64_t priorities_sent_ = 0;
  int64_t env_steps_ = 0;
  int64_t request_timeouts_ = 0;
  int64_t stale_replies_ = 0;
  std::vector<float> flat_;
  // The policy's parameters averaged over about policy_average updates (when that is > 0).
  std::optional<ParameterAverage> average_;
  // Checkpoint files on disk, oldest first: those of earlier lives found at the start (by
  // update), then this life's.
  std::deque<std::string> written_;

  // Stats since the last stats message.
  double loss_sum_ = 0, q_sum_ = 0;
  int64_t stat_updates_ = 0;
  RateMeter updates_rate_;
};

}  // namespace rl::learner
