// Actor: runs environments with an exploring policy (policy.h: epsilon-greedy for discrete
// actions, Gaussian noise for continuous ones) and publishes their transitions.
//
// It steps envs_per_actor environments in turn, acts with the newest complete weights version
// from the learner (uniformly at random until the first one arrives), turns steps into n-step
// transitions and publishes them in batches (transition_batch_t) on RL_TRANSITIONS. Actions go out
// as EnvSpec::action_width() floats. Pixel envs (EnvSpec::frame_stack > 0) send every frame once,
// with an actor-local id, and transitions name their stacks by frame id. While the replay's rate
// limiter says so (RL_FLOW), it pauses. It publishes stats_actor_t a few times per second.
//
// Its step count, which drives the exploration schedule (epsilon annealing, sigma annealing,
// the random start), carries on across restarts: an actor takes no step before the replay's
// first flow message, and takes up from it the transitions the replay holds from its actor id,
// one per step of its earlier lives (a stopping actor flushes its unfinished n-step returns as
// truncations, so every step goes out). A restarted actor, a resumed run and a requeued one on
// another host all continue the schedule where it was.
//
// Single-threaded: the thread that calls Run() also handles LCM.
#pragma once

#include <cstdint>
#include <deque>
#include <limits>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "actor/exploration.h"
#include "actor/nstep.h"
#include "actor/policy.h"
#include "actor/weights_assembler.h"
#include "common/clock.h"
#include "common/lcm_bus.h"
#include "envs/env.h"
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
  ExplorationConfig exploration;       // how the policy explores (epsilon or noise)
  double stats_hz = 4.0;               // stats messages per second
  int64_t max_steps = 0;               // stop after this many env steps (0: run until stopped)
  bool clip_rewards = false;           // clamp each step's reward to [-1, 1] in transitions
  // A second environment for the episodes that begin once this actor has taken
  // `later_env_after` steps (its earlier lives included): a schedule of training rules, such as
  // CarRacing's off-track rule, which speeds early learning, dropped once the policy drives. It
  // must give the observations and actions env_id gives. "": env_id throughout.
  std::string later_env_id;
  int64_t later_env_after = 0;

  // Throws std::invalid_argument naming the bad field.
  void Validate() const;
};

// Seconds a starting actor withholds its stats while it waits for the replay's first flow
// message, which gives it the step count it continues from (Actor::OnFlow), so that its stats
// never show a count restarting at 0. After that it publishes them anyway (their drop counters
// say why no flow message arrives).
inline constexpr double kStatsHoldSeconds = 10.0;

// Seed of the first reset of environment `env_index` of actor `actor_id`: distinct for every
// env of every actor of a run, and below 10^9, where the evaluator's seeds begin.
uint64_t TrainingSeed(uint64_t run_seed, int actor_id, int env_index);

class Actor {
 public:
  // Subscribes to weights and flow control on `bus`, which must outlive the actor. Throws
  // std::invalid_argument for a bad config or an exploration that does not fit the env's actions.
  Actor(ActorConfig config, Bus* bus);
  Actor(const Actor&) = delete;
  Actor& operator=(const Actor&) = delete;
  ~Actor();

  // Acts, publishes and handles LCM until StopRequested() or max_steps.
  void Run();

  // Steps every environment once and publishes full batches. Returns the env steps taken.
  int StepEnvs();

  void PublishStats();

  /// Env steps of this actor id, earlier lives included once the first flow message came.
  int64_t env_steps() const { return env_steps_; }
  /// Whether the replay's first flow message came and the step count was taken up from it.
  bool count_taken_up() const { return counted_; }
  int64_t episodes() const { return episodes_; }
  int64_t weights_version() const { return weights_version_; }
  // The exploration scale now: epsilon, or the noise sigma (1 during the random start).
  double exploration() const { return policy_->exploration(env_steps_); }
  /// Weights versions refused: of a network that does not build or fit the env, or whose
  /// chunks claim another size than that network's (actor/weights_assembler.h).
  int64_t weights_refused() const { return assembler_.refused() + weights_refused_; }
  /// Transitions published so far.
  int64_t published() const { return published_; }
  /// Whether the replay's flow control holds this actor: no flow message yet, insert_allowed is
  /// 0, or the actor has used its share of the insert credit of the last flow message (OnFlow).
  bool paused() const { return !insert_allowed_ || published_ >= insert_limit_; }
  /// Transitions this actor may have published in all before it waits for the next flow message.
  int64_t insert_limit() const { return insert_limit_; }
  double mean_return() const;

 private:
  // Takes the replay's flow control: insert_allowed, and this actor's share of the insert
  // credit, credit / num_actors (rounded up), less its transitions still on the way (published
  // but not yet stored by the replay, as far as the message says). A count of stored
  // transitions that goes back means a restarted replay (from its snapshot, or empty): what
  // was published until then is taken as lost, not as on the way.
  void OnFlow(const rlmsg::flow_control_t& f);
  // At the first flow message: carries on the step count of this actor id's earlier lives (a
  // restart, a resumed run, a requeue on another host). The replay has stored `stored`
  // transitions of this id, one per step taken, so the schedules (exploration, random start)
  // and the step count continue from there instead of starting again at 0. Never lowers
  // the count.
  void TakeUpCount(int64_t stored);
  // Emits the pending n-step transitions of every env as truncated (the actor stops).
  void FlushEpisodes();

  // How one env's transitions carry its observations, chosen once from the env's spec: the
  // observation's floats (flat envs), or the ids of the frames of its stack, each new frame
  // queued into the batch once (pixel envs). It holds the env's n-step accumulator; the
  // implementations are in actor.cc.
  class ObservationEncoder {
   public:
    virtual ~ObservationEncoder() = default;
    // The env was reset: its observation starts an episode.
    virtual void Start(const envs::Env& env) = 0;
    // The env took `action` from the last observation and gave `reward` and a new observation:
    // records the step and appends the transitions it completes to the batch.
    virtual void Step(const envs::Env& env, std::span<const float> action, double reward,
                      bool terminated, bool truncated, int64_t episode_id) = 0;
    // Appends the pending transitions as truncated ones (the actor stops).
    virtual void Flush(int64_t episode_id) = 0;
  };
  template <class Codec>
  class Encoder;

  struct EnvSlot {
    std::unique_ptr<envs::Env> env;
    std::vector<float> action;  // action_width floats
    std::unique_ptr<ObservationEncoder> encoder;
    double episode_return = 0;
    int64_t episode_id = 0;
    bool later = false;  // env is the later env
  };

  void OnWeights(const rlmsg::weights_chunk_t& chunk);
  // The assembler's SizeOf: the parameter floats of a network of `architecture` that fits the
  // env (the policy's own, or a candidate built now and kept for when its version completes),
  // or -1 with the reason logged.
  int64_t WeightsSize(const std::string& architecture);
  // Puts the later env in slot `s` at an episode's end and resets it (the first reset of slot
  // j: TrainingSeed(seed, actor_id, j) + an offset); says so for slot 0.
  void TakeLaterEnv(EnvSlot* s);
  // The encoder of an env of this actor's spec.
  std::unique_ptr<ObservationEncoder> MakeEncoder();
  // Appends a transition's other fields to the batch (its encoder has appended its
  // observations), and publishes the batch when it is full.
  void Append(std::span<const float> action, float reward, float discount, int64_t episode_id);
  void PublishBatch();

  ActorConfig config_;
  Bus* bus_;
  envs::EnvSpec spec_;
  std::vector<EnvSlot> slots_;
  std::unique_ptr<Policy> policy_;
  WeightsAssembler assembler_;
  // A network of an architecture other than the policy's, built when the first chunk of its
  // version arrived; the policy takes it when the version completes.
  std::optional<nn::Sequential> candidate_;
  int64_t weights_version_ = -1;
  int64_t weights_refused_ = 0;

  // Nothing is published before the replay's first flow message: an actor can step far faster
  // than the replay stores, and would otherwise fill the replay's socket queue before the
  // replay has read enough to tell it to stop.
  bool insert_allowed_ = true;
  int64_t insert_limit_ = 0;
  // Whether the first flow message came (and the step count was taken up from it).
  bool counted_ = false;
  int64_t env_steps_ = 0;
  int64_t episodes_ = 0;
  int64_t published_ = 0;
  // The replay's count of this actor's stored transitions in the last flow message, and the
  // transitions published that a restarted replay lost (never to be stored).
  int64_t last_stored_ = 0;
  int64_t lost_ = 0;
  std::deque<double> recent_returns_;  // last 100 episode returns
  rlmsg::transition_batch_t batch_{};
  // Pixel envs: the id of this actor's next frame (shared by its envs).
  int64_t next_frame_id_ = 0;

  RateMeter steps_rate_;
};

}  // namespace rl::actor
