#include "actor/actor.h"

#include <algorithm>
#include <cstdio>
#include <limits>
#include <numeric>
#include <stdexcept>
#include <utility>

#include "common/channels.h"
#include "common/clock.h"
#include "common/shutdown.h"
#include "envs/registry.h"
#include "envs/specs.h"
#include "rlmsg/flow_control_t.hpp"
#include "rlmsg/stats_actor_t.hpp"

namespace rl::actor {

void ActorConfig::Validate() const {
  exploration.Validate();
  if (num_actors < 1) throw std::invalid_argument("num-actors must be >= 1");
  if (actor_id < 0 || actor_id >= num_actors) {
    throw std::invalid_argument("actor-id must be in [0, num-actors)");
  }
  if (envs_per_actor < 1 || envs_per_actor > 100) {
    throw std::invalid_argument("envs-per-actor must be in [1, 100]");
  }
  if (batch_size < 1) throw std::invalid_argument("batch-size must be >= 1");
  if (n_step < 1) throw std::invalid_argument("n-step must be >= 1");
  if (!(gamma >= 0 && gamma <= 1)) throw std::invalid_argument("gamma must be in [0, 1]");
  if (!(stats_hz > 0)) throw std::invalid_argument("stats-hz must be > 0");
  if (later_env_after < 0) throw std::invalid_argument("later-env-after must be >= 0");
}

uint64_t TrainingSeed(uint64_t run_seed, int actor_id, int env_index) {
  return (run_seed % 1000) * 1000000 + static_cast<uint64_t>(actor_id) * 100 +
         static_cast<uint64_t>(env_index);
}

namespace {

// Added to TrainingSeed for the first reset of a later env, so that its episodes are not those
// the first env played (below 10^9 with any run seed, and distinct for up to 5,000 actors).
constexpr uint64_t kLaterEnvSeedOffset = 500000;

// Flat envs: a transition carries the observation's floats.
struct FlatCodec {
  using Value = float;
  static int Size(const envs::EnvSpec& spec) { return spec.observation_size; }
  // The observation after a reset.
  void First(const envs::Env& env, std::vector<float>* obs) const {
    const std::span<const float> o = env.observation();
    obs->assign(o.begin(), o.end());
  }
  // The observation after a step from `obs`.
  void Next(const envs::Env& env, std::span<const float> /*obs*/, std::vector<float>* next) const {
    First(env, next);
  }
  static void Write(const Transition& t, rlmsg::transition_batch_t* batch) {
    batch->obs.insert(batch->obs.end(), t.obs.begin(), t.obs.end());
    batch->next_obs.insert(batch->next_obs.end(), t.next_obs.begin(), t.next_obs.end());
  }
};

// Pixel envs: a transition carries the ids of the frames of its stacks, oldest first; each new
// frame goes into the batch once, under the actor's next frame id.
struct FrameCodec {
  using Value = int64_t;
  rlmsg::transition_batch_t* batch;
  int64_t* next_id;

  static int Size(const envs::EnvSpec& spec) { return spec.frame_stack; }
  // Queues the env's newest frame and returns its id.
  int64_t Add(const envs::Env& env) const {
    const std::span<const uint8_t> f = env.frame();
    batch->frames.insert(batch->frames.end(), f.begin(), f.end());
    batch->frame_id.push_back(*next_id);
    return (*next_id)++;
  }
  // After a reset the env repeats its first frame to fill the stack; the ids say the same.
  void First(const envs::Env& env, std::vector<int64_t>* stack) const {
    std::fill(stack->begin(), stack->end(), Add(env));
  }
  // The stack after a step: the old one shifted by one, then the new frame.
  void Next(const envs::Env& env, std::span<const int64_t> stack,
            std::vector<int64_t>* next) const {
    std::copy(stack.begin() + 1, stack.end(), next->begin());
    next->back() = Add(env);
  }
  static void Write(const FrameTransition& t, rlmsg::transition_batch_t* batch) {
    batch->obs_frames.insert(batch->obs_frames.end(), t.obs.begin(), t.obs.end());
    batch->next_obs_frames.insert(batch->next_obs_frames.end(), t.next_obs.begin(),
                                  t.next_obs.end());
  }
};

}  // namespace

template <class Codec>
class Actor::Encoder final : public Actor::ObservationEncoder {
 public:
  using Value = typename Codec::Value;

  Encoder(Actor* actor, Codec codec)
      : actor_(actor),
        codec_(codec),
        nstep_(actor->config_.n_step, actor->config_.gamma, Codec::Size(actor->spec_),
               actor->spec_.action_width()),
        obs_(static_cast<size_t>(Codec::Size(actor->spec_))),
        next_(obs_.size()) {}

  void Start(const envs::Env& env) override { codec_.First(env, &obs_); }

  void Step(const envs::Env& env, std::span<const float> action, double reward, bool terminated,
            bool truncated, int64_t episode_id) override {
    codec_.Next(env, obs_, &next_);
    nstep_.Add(obs_, action, reward, next_, terminated, truncated, Sink(episode_id));
    obs_.swap(next_);
  }

  void Flush(int64_t episode_id) override { nstep_.Flush(Sink(episode_id)); }

 private:
  // Appends each transition to the actor's batch.
  typename BasicNStepAccumulator<Value>::Sink Sink(int64_t episode_id) {
    return [this, episode_id](const BasicTransition<Value>& t) {
      Codec::Write(t, &actor_->batch_);
      actor_->Append(t.action, t.reward, t.discount, episode_id);
    };
  }

  Actor* actor_;
  Codec codec_;
  BasicNStepAccumulator<Value> nstep_;
  std::vector<Value> obs_;   // the observation the next step starts from
  std::vector<Value> next_;  // scratch for the one it ends in
};

std::unique_ptr<Actor::ObservationEncoder> Actor::MakeEncoder() {
  if (spec_.frame_stack > 0) {
    return std::make_unique<Encoder<FrameCodec>>(this, FrameCodec{&batch_, &next_frame_id_});
  }
  return std::make_unique<Encoder<FlatCodec>>(this, FlatCodec{});
}

Actor::Actor(ActorConfig config, Bus* bus)
    : config_(std::move(config)),
      bus_(bus),
      assembler_([this](const std::string& architecture) { return WeightsSize(architecture); }) {
  config_.Validate();
  for (int j = 0; j < config_.envs_per_actor; ++j) {
    EnvSlot& s = slots_.emplace_back();
    s.env = envs::MakeEnv(config_.env_id);
    spec_ = s.env->spec();
    s.env->Reset(TrainingSeed(config_.seed, config_.actor_id, j));
    s.action.resize(static_cast<size_t>(spec_.action_width()));
    s.encoder = MakeEncoder();
    s.encoder->Start(*s.env);
  }
  if (!config_.later_env_id.empty() &&
      !envs::SameShape(envs::LookupSpec(config_.later_env_id), spec_)) {
    throw std::invalid_argument("later-env '" + config_.later_env_id +
                                "' gives other observations or actions than env '" +
                                config_.env_id + "'");
  }
  policy_ = MakePolicy(spec_, config_.exploration, config_.actor_id, config_.num_actors,
                       TrainingSeed(config_.seed, config_.actor_id, 99));
  batch_.actor_id = config_.actor_id;
  batch_.action_width = spec_.action_width();
  // The observations' shape: floats per observation, or the frames' geometry.
  batch_.obs_size = spec_.frame_stack > 0 ? 0 : spec_.observation_size;
  batch_.height = spec_.frame_height;
  batch_.width = spec_.frame_width;
  batch_.stack = spec_.frame_stack;

  bus_->Subscribe<rlmsg::weights_chunk_t>(
      channels::kWeights, [this](const rlmsg::weights_chunk_t& c) { OnWeights(c); }, Port::kBulk);
  bus_->Subscribe<rlmsg::flow_control_t>(channels::kFlow,
                                         [this](const rlmsg::flow_control_t& f) { OnFlow(f); });
}

Actor::~Actor() = default;

void Actor::OnFlow(const rlmsg::flow_control_t& f) {
  // Counts far beyond any run's (2^62) are capped, so that no sum below overflows.
  constexpr int64_t kMaxCount = int64_t{1} << 62;
  int64_t stored = 0;
  for (size_t i = 0; i < f.actor_id.size(); ++i) {
    if (f.actor_id[i] == config_.actor_id) stored = std::min(f.actor_inserts[i], kMaxCount);
  }
  if (!counted_) TakeUpCount(stored);
  insert_allowed_ = f.insert_allowed != 0;
  if (f.insert_credit < 0) {
    insert_limit_ = std::numeric_limits<int64_t>::max();
    return;
  }
  const int64_t actors = std::max(config_.num_actors, 1);
  const int64_t share = (std::min(f.insert_credit, kMaxCount) + actors - 1) / actors;
  // A restarted replay (from its snapshot, or empty) stores less than it did: what this actor
  // published until now is stored or lost, not on the way.
  if (stored < last_stored_) lost_ = std::max<int64_t>(0, published_ - stored);
  last_stored_ = stored;
  // A restarted actor may find more stored under its id than it has published: nothing of its
  // own is then on the way.
  const int64_t on_the_way = std::max<int64_t>(0, published_ - lost_ - stored);
  insert_limit_ = published_ + std::max<int64_t>(0, share - on_the_way);
}

int64_t Actor::WeightsSize(const std::string& architecture) {
  if (policy_->has_network() && architecture == policy_->network().Architecture()) {
    return policy_->network().FlatSize();
  }
  if (candidate_ && candidate_->Architecture() == architecture) return candidate_->FlatSize();
  // Built within nn's limits (sequential.h), as large as the network the policy would hold.
  std::string why;
  try {
    std::mt19937 init_rng(0);
    nn::Sequential net = nn::BuildFromArchitecture(architecture, &init_rng);
    why = policy_->CheckNetwork(net);
    if (why.empty()) candidate_ = std::move(net);
  } catch (const std::invalid_argument& e) {
    why = e.what();
  }
  if (!why.empty()) {
    if (assembler_.refused() < 10) {
      std::fprintf(stderr, "[actor-%d] refused weights '%.200s': %s\n", config_.actor_id,
                   architecture.c_str(), why.c_str());
    }
    return -1;
  }
  return candidate_->FlatSize();
}

void Actor::TakeUpCount(int64_t stored) {
  counted_ = true;
  last_stored_ = stored;
  if (stored <= env_steps_) return;
  // Every step became one transition (a stopping actor flushes its episodes), so the earlier
  // lives of this actor id took at least `stored` steps and published as many.
  env_steps_ = stored;
  published_ = std::max(published_, stored);
  std::printf(
      "actor-%d: continuing at step %lld (the replay holds %lld transitions of "
      "actor %d), %s %.5f\n",
      config_.actor_id, static_cast<long long>(env_steps_), static_cast<long long>(stored),
      config_.actor_id, spec_.continuous() ? "sigma" : "epsilon", exploration());
  std::fflush(stdout);
}

void Actor::FlushEpisodes() {
  for (EnvSlot& s : slots_) s.encoder->Flush(s.episode_id);
}

void Actor::OnWeights(const rlmsg::weights_chunk_t& chunk) {
  if (!assembler_.Add(chunk)) return;
  std::optional<Weights> w = assembler_.Take();
  if (!w) return;
  if (!policy_->has_network() || w->architecture != policy_->network().Architecture()) {
    // The candidate built for this architecture, or (when another one replaced it meanwhile)
    // the same network built again.
    if (!candidate_ || candidate_->Architecture() != w->architecture) {
      candidate_.reset();
      if (WeightsSize(w->architecture) < 0) {
        ++weights_refused_;
        return;
      }
    }
    policy_->SetNetwork(std::move(*candidate_));
    candidate_.reset();
  }
  policy_->network().SetFlat(w->params.data(), w->params.size());
  weights_version_ = w->version;
}

void Actor::Append(std::span<const float> action, float reward, float discount,
                   int64_t episode_id) {
  batch_.action.insert(batch_.action.end(), action.begin(), action.end());
  batch_.reward.push_back(reward);
  batch_.discount.push_back(discount);
  batch_.episode_id.push_back(episode_id);
  batch_.priority.push_back(0.0f);
  if (static_cast<int>(batch_.reward.size()) >= config_.batch_size) PublishBatch();
}

void Actor::PublishBatch() {
  rlmsg::transition_batch_t& b = batch_;
  b.count = static_cast<int32_t>(b.reward.size());
  b.num_values = static_cast<int32_t>(b.obs.size());
  b.num_frames = static_cast<int32_t>(b.frame_id.size());
  b.num_bytes = static_cast<int32_t>(b.frames.size());
  b.num_refs = static_cast<int32_t>(b.obs_frames.size());
  b.num_action_values = static_cast<int32_t>(b.action.size());
  if (b.count == 0 && b.num_frames == 0) return;
  bus_->Publish(channels::kTransitions, &b);
  published_ += b.count;
  for (auto* v : {&b.obs, &b.next_obs, &b.action, &b.reward, &b.discount, &b.priority}) v->clear();
  for (auto* v : {&b.frame_id, &b.obs_frames, &b.next_obs_frames, &b.episode_id}) v->clear();
  b.frames.clear();
}

int Actor::StepEnvs() {
  for (EnvSlot& s : slots_) {
    policy_->Act(s.env->observation(), env_steps_, s.action);
    const envs::StepResult r = s.env->Step(s.action);
    s.episode_return += r.reward;
    const double reward = config_.clip_rewards ? std::clamp(r.reward, -1.0, 1.0) : r.reward;
    s.encoder->Step(*s.env, s.action, reward, r.terminated, r.truncated, s.episode_id);
    if (r.terminated || r.truncated) {
      recent_returns_.push_back(s.episode_return);
      if (recent_returns_.size() > 100) recent_returns_.pop_front();
      ++episodes_;
      ++s.episode_id;
      s.episode_return = 0;
      if (!s.later && !config_.later_env_id.empty() && env_steps_ >= config_.later_env_after) {
        TakeLaterEnv(&s);
      } else {
        s.env->Reset();
      }
      s.encoder->Start(*s.env);
    }
  }
  env_steps_ += static_cast<int64_t>(slots_.size());
  return static_cast<int>(slots_.size());
}

void Actor::TakeLaterEnv(EnvSlot* s) {
  const auto j = static_cast<int>(s - slots_.data());
  s->env = envs::MakeEnv(config_.later_env_id);
  s->env->Reset(TrainingSeed(config_.seed, config_.actor_id, j) + kLaterEnvSeedOffset);
  s->later = true;
  if (j == 0) {
    std::printf("actor-%d: after %lld steps, its episodes are on %s from now on\n",
                config_.actor_id, static_cast<long long>(env_steps_) + 1,
                config_.later_env_id.c_str());
    std::fflush(stdout);
  }
}

double Actor::mean_return() const {
  if (recent_returns_.empty()) return 0.0;
  return std::accumulate(recent_returns_.begin(), recent_returns_.end(), 0.0) /
         static_cast<double>(recent_returns_.size());
}

void Actor::PublishStats() {
  const double now = MonoSeconds();
  rlmsg::stats_actor_t s{};
  s.actor_id = config_.actor_id;
  s.env_steps = env_steps_;
  s.episodes = episodes_;
  s.steps_per_second = steps_rate_.Take(env_steps_, now);
  s.mean_return = mean_return();
  s.epsilon = exploration();
  s.weights_version = weights_version_;
  s.paused = paused() ? 1 : 0;
  s.transitions_published = published_;
  bus_->FillCounters(&s);
  bus_->Publish(channels::kStatsActor, &s);
}

void Actor::Run() {
  const double stats_period = 1.0 / config_.stats_hz;
  const double start = MonoSeconds();
  double next_stats = start;
  double next_log = start + 5.0;
  while (!StopRequested()) {
    if (config_.max_steps > 0 && env_steps_ >= config_.max_steps) break;
    if (!paused()) {
      // Step until a batch went out (or a bounded number of steps), then look at LCM.
      const int64_t before = published_;
      for (int i = 0; i < config_.batch_size && published_ == before; ++i) StepEnvs();
      bus_->Handle(0);
    } else {
      bus_->Handle(5);
    }
    const double now = MonoSeconds();
    if (now >= next_stats) {
      // Until the step count is taken up, a stats message would show a count from 0.
      if (counted_ || now - start >= kStatsHoldSeconds) PublishStats();
      next_stats = now + stats_period;
    }
    if (now >= next_log) {
      std::printf("actor-%d: steps %lld episodes %lld mean return %.1f %s %.4f weights %lld%s\n",
                  config_.actor_id, static_cast<long long>(env_steps_),
                  static_cast<long long>(episodes_), mean_return(),
                  spec_.continuous() ? "sigma" : "epsilon", exploration(),
                  static_cast<long long>(weights_version_), paused() ? " (paused)" : "");
      std::fflush(stdout);
      next_log = now + 5.0;
    }
  }
  // Every step taken goes out: the count a restarted actor takes up from the replay is then
  // this one.
  FlushEpisodes();
  PublishBatch();
  if (counted_ || MonoSeconds() - start >= kStatsHoldSeconds) PublishStats();
}

}  // namespace rl::actor
