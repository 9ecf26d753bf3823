#include "learner/learner.h"

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <stdexcept>
#include <string_view>
#include <utility>
#include <vector>

#include "common/atomic_file.h"
#include "common/channels.h"
#include "common/clock.h"
#include "common/shutdown.h"
#include "envs/specs.h"
#include "learner/algorithm_state.h"
#include "nn/checkpoint.h"
#include "nn/parallel.h"
#include "nn/precision.h"
#include "rlmsg/checkpoint_t.hpp"
#include "rlmsg/sample_request_t.hpp"
#include "rlmsg/stats_learner_t.hpp"

namespace rl::learner {
namespace {

// The chosen algorithm (Validate() has checked its name), in the learner's precision.
std::unique_ptr<Algorithm> MakeAlgorithm(const LearnerConfig& c, const envs::EnvSpec& spec) {
  std::unique_ptr<Algorithm> made;
  ForEachAlgorithm(c.algorithms, [&](const auto& config) {
    if (c.algorithm != config.kName) return;
    auto chosen = config;
    chosen.precision = nn::ParsePrecision(c.precision);
    made = chosen.Make(spec);
  });
  return made;
}

}  // namespace

void LearnerConfig::Validate() const {
  CheckAlgorithmName(algorithm);
  ForEachAlgorithm(algorithms, [&](const auto& config) {
    if (algorithm == config.kName) config.Validate();
  });
  if (augment_shift < 0) throw std::invalid_argument("augment-shift must be >= 0");
  if (batch_size < 1 || batch_size > 65536) throw std::invalid_argument("batch-size in [1, 65536]");
  if (requests_in_flight < 1) throw std::invalid_argument("requests-in-flight must be >= 1");
  if (!(request_timeout > 0)) throw std::invalid_argument("request-timeout must be > 0");
  if (weights_every < 1) throw std::invalid_argument("weights-every must be >= 1");
  if (checkpoint_every < 1) throw std::invalid_argument("checkpoint-every must be >= 1");
  if (keep_checkpoints < 0) throw std::invalid_argument("keep-checkpoints must be >= 0");
  if (policy_average < 0) throw std::invalid_argument("policy-average must be >= 0");
  if (learning_rate_decay_updates < 0) {
    throw std::invalid_argument("learning-rate-decay-updates must be >= 0");
  }
  if (!(learning_rate_end >= 0 && learning_rate_end <= 1)) {
    throw std::invalid_argument("learning-rate-end must be in [0, 1]");
  }
  if (!(stats_hz > 0)) throw std::invalid_argument("stats-hz must be > 0");
  if (threads < 1 || threads > 64) throw std::invalid_argument("threads must be in [1, 64]");
  if (precision != "auto") nn::ParsePrecision(precision);
}

float LearningRateScale(int64_t updates, int64_t decay_updates, double end) {
  if (decay_updates <= 0) return 1.0f;
  const double done =
      static_cast<double>(std::min(updates, decay_updates)) / static_cast<double>(decay_updates);
  return static_cast<float>(1.0 - (1.0 - end) * done);
}

Learner::Learner(LearnerConfig config, Bus* bus)
    : config_(Resolved(std::move(config))),
      bus_(bus),
      spec_(envs::LookupSpec(config_.env_id)),
      algorithm_(MakeAlgorithm(config_, spec_)),
      decoder_(spec_, config_.augment_shift, config_.seed + 7),
      weights_(bus),
      sender_(bus->config().sender) {
  nn::SetNumThreads(config_.threads);
  if (config_.policy_average > 0) average_.emplace(config_.policy_average);
  const std::string checkpoints = (std::filesystem::path(config_.out_dir) / "checkpoints").string();
  std::filesystem::create_directories(checkpoints);
  // An earlier life killed while it wrote a checkpoint or the state left its temporary file.
  RemoveStaleTemporaries(checkpoints);
  // The checkpoints that earlier lives of the learner (a restart, a resumed run) left there count
  // towards keep_checkpoints, and go first.
  const std::vector<std::string> earlier = nn::CheckpointFilesIn(checkpoints);
  written_.assign(earlier.begin(), earlier.end());
  if (config_.resume && std::filesystem::exists(StatePath())) {
    LoadState(StateFile::Load(StatePath(), StateKind()));
    resumed_ = true;
  }
  bus_->Subscribe<rlmsg::sample_batch_t>(
      channels::kSamples, [this](rlmsg::sample_batch_t& m) { OnSamples(m); }, Port::kSamples);
}

bool Learner::Accept(const std::string& requester, int64_t request_id, int64_t total_inserts) {
  if (requester != sender_) return false;  // another learner's reply
  auto it = in_flight_.find(request_id);
  if (it == in_flight_.end()) {
    ++stale_replies_;  // answered twice after a retry
    return false;
  }
  in_flight_.erase(it);
  env_steps_ = std::max(env_steps_, total_inserts);
  return true;
}

void Learner::OnSamples(rlmsg::sample_batch_t& m) {
  if (!Accept(m.requester, m.request_id, m.total_inserts)) return;
  if (spare_.empty()) {
    ready_.emplace_back();
  } else {
    ready_.push_back(std::move(spare_.back()));
    spare_.pop_back();
  }
  std::swap(ready_.back(), m);
}

void Learner::PublishPriorities(const std::vector<int64_t>& index) {
  const std::vector<float>& td = algorithm_->last_td_errors();
  priorities_.count = static_cast<int32_t>(index.size());
  priorities_.index = index;
  priorities_.priority.assign(td.begin(), td.end());
  bus_->Publish(channels::kPriorities, &priorities_);
  priorities_sent_ += priorities_.count;
}

void Learner::SendRequest(int64_t id) {
  rlmsg::sample_request_t r{};
  r.request_id = id;
  r.batch_size = config_.batch_size;
  bus_->Publish(channels::kSampleRequest, &r);
}

void Learner::TopUpRequests(double now) {
  for (auto& [id, req] : in_flight_) {
    if (now - req.sent > config_.request_timeout) {
      ++request_timeouts_;
      req.sent = now;
      SendRequest(id);
    }
  }
  // Keep requests_in_flight outstanding, counting the batches received but not yet trained on.
  while (static_cast<int>(in_flight_.size() + ready_.size()) < config_.requests_in_flight) {
    const int64_t id = next_request_id_++;
    in_flight_[id].sent = now;
    SendRequest(id);
  }
}

void Learner::TrainOn(const rlmsg::sample_batch_t& m) {
  // A reply that does not fit (a foreign run's replay, a replay of another env) is dropped and
  // counted, never trained on and never fatal.
  Batch batch;
  const char* why = decoder_.Decode(m, &batch);
  UpdateResult r;
  if (why == nullptr) {
    if (config_.learning_rate_decay_updates > 0) {
      algorithm_->SetLearningRateScale(LearningRateScale(
          algorithm_->updates(), config_.learning_rate_decay_updates, config_.learning_rate_end));
    }
    try {
      r = algorithm_->Update(batch);
    } catch (const std::invalid_argument& e) {
      why = "the algorithm refused it";
      if (batches_refused_ < 10) std::fprintf(stderr, "[%s] %s\n", sender_.c_str(), e.what());
    }
  }
  if (why != nullptr) {
    if (batches_refused_++ < 10 || batches_refused_ % 1000 == 0) {
      std::fprintf(stderr, "[%s] refused a sample batch: %s\n", sender_.c_str(), why);
    }
    return;
  }
  if (config_.prioritized) PublishPriorities(m.index);
  if (average_) {
    algorithm_->policy().GetFlat(&flat_);
    average_->Add(flat_);
  }
  loss_sum_ += r.loss;
  q_sum_ += r.mean_q;
  ++stat_updates_;
}

std::string Learner::StatePath(const LearnerConfig& c) {
  return (std::filesystem::path(c.out_dir) / "checkpoints" / nn::kLearnerStateFile).string();
}

std::string Learner::StatePath() const { return StatePath(config_); }

LearnerConfig Learner::Resolved(LearnerConfig c) {
  c.Validate();
  if (c.precision != "auto") return c;
  // A resumed run goes on in the precision it was trained in, whatever this CPU runs fast (the
  // state is read twice then: once here, once by LoadState).
  if (c.resume && std::filesystem::exists(StatePath(c))) {
    const StateFile state = StateFile::Load(StatePath(c), StateKind(c));
    c.precision = state.Has("learner.precision") ? state.Text("learner.precision") : "fp32";
  } else {
    c.precision = nn::NativeBf16() ? "bf16" : "fp32";
  }
  return c;
}

std::string Learner::StateKind() const { return StateKind(config_); }

std::string Learner::StateKind(const LearnerConfig& c) { return "learner " + c.algorithm; }

StateFile Learner::SaveState() const {
  StateFile state(StateKind());
  state.PutText("learner.env", config_.env_id);
  state.PutText("learner.precision", config_.precision);
  state.PutInt("learner.env_steps", env_steps_);
  state.PutText("learner.wall_seconds", std::to_string(MonoSeconds() - start_time_));
  PutRng(&state, "learner.shift_rng", decoder_.shift_rng());
  // The last reply heard from each replay, so that a restarted learner refuses recorded replies
  // older than this state (common/lcm_bus.h).
  state.PutText("learner.bus_positions", bus_->SavePositions());
  if (average_) average_->Save(&state, "learner.policy_average");
  algorithm_->SaveState(&state);
  return state;
}

void Learner::LoadState(const StateFile& state) {
  if (state.Text("learner.env") != config_.env_id) {
    throw std::runtime_error("the saved learner state is of env " + state.Text("learner.env") +
                             ", this run's is " + config_.env_id);
  }
  // States written before the option existed were trained in fp32.
  const std::string precision =
      state.Has("learner.precision") ? state.Text("learner.precision") : "fp32";
  if (precision != config_.precision) {
    throw std::runtime_error("the saved learner state was trained with precision " + precision +
                             ", this run's is " + config_.precision +
                             ": resume with the same precision, or start afresh");
  }
  algorithm_->LoadState(state);
  env_steps_ = state.Int("learner.env_steps");
  resumed_wall_seconds_ = std::stod(state.Text("learner.wall_seconds"));
  GetRng(state, "learner.shift_rng", &decoder_.shift_rng());
  // States written before the bus kept positions have none.
  if (state.Has("learner.bus_positions")) bus_->LoadPositions(state.Text("learner.bus_positions"));
  // A state saved without an average (the option was off) starts one at the next update.
  if (average_) {
    average_->Load(state, "learner.policy_average", algorithm_->policy().FlatSize());
  }
}

std::string Learner::Checkpoint() {
  std::string path = (std::filesystem::path(config_.out_dir) / "checkpoints" /
                      nn::CheckpointFileName(algorithm_->updates()))
                         .string();
  nn::Checkpoint ckpt;
  ckpt.architecture = algorithm_->policy().Architecture();
  ckpt.meta.update = algorithm_->updates();
  ckpt.meta.env_steps = env_steps_;
  ckpt.meta.wall_seconds = MonoSeconds() - start_time_;
  ckpt.meta.run_id = static_cast<uint64_t>(bus_->config().run_id);
  ckpt.meta.note = "env = " + config_.env_id + "\nprecision = " + config_.precision;
  if (config_.learning_rate_decay_updates > 0) {
    char scale[32];
    std::snprintf(scale, sizeof scale, "%.4g",
                  LearningRateScale(algorithm_->updates(), config_.learning_rate_decay_updates,
                                    config_.learning_rate_end));
    ckpt.meta.note += std::string("\nlearning rates = ") + scale + " of their start";
  }
  if (!average_ || average_->values().empty()) {
    algorithm_->policy().GetFlat(&ckpt.params);
  } else {
    ckpt.params = average_->values();
    ckpt.meta.note +=
        "\npolicy = the average of about " + std::to_string(config_.policy_average) + " updates";
  }
  nn::SaveCheckpoint(path, ckpt);
  SaveState().Save(StatePath());
  // Keep the newest keep_checkpoints files (this life's last, earlier lives' before them); older
  // ones have been scored or skipped by now.
  written_.erase(std::remove(written_.begin(), written_.end(), path), written_.end());
  written_.push_back(path);
  while (config_.keep_checkpoints > 0 &&
         static_cast<int>(written_.size()) > config_.keep_checkpoints) {
    std::error_code ignored;
    std::filesystem::remove(written_.front(), ignored);
    written_.pop_front();
  }

  rlmsg::checkpoint_t announce{};
  announce.path = path;
  announce.update = ckpt.meta.update;
  announce.env_steps = ckpt.meta.env_steps;
  announce.wall_seconds = ckpt.meta.wall_seconds;
  bus_->Publish(channels::kCheckpoint, &announce);
  return path;
}

void Learner::PublishStats(double now) {
  rlmsg::stats_learner_t s{};
  s.updates = algorithm_->updates();
  s.updates_per_second = updates_rate_.Take(s.updates, now);
  s.samples_per_second = s.updates_per_second * config_.batch_size;
  s.loss = stat_updates_ > 0 ? loss_sum_ / static_cast<double>(stat_updates_) : 0.0;
  s.mean_q = stat_updates_ > 0 ? q_sum_ / static_cast<double>(stat_updates_) : 0.0;
  s.weights_version = weights_.published_version();
  s.env_steps = env_steps_;
  s.request_timeouts = request_timeouts_;
  s.priorities_sent = priorities_sent_;
  bus_->FillCounters(&s);
  s.dropped_invalid += batches_refused_;
  bus_->Publish(channels::kStatsLearner, &s);
  loss_sum_ = q_sum_ = 0;
  stat_updates_ = 0;
}

void Learner::Run() {
  // A resumed learner's wall time continues from its saved state.
  start_time_ = MonoSeconds() - resumed_wall_seconds_;
  const double stats_period = 1.0 / config_.stats_hz;
  double next_stats = start_time_;
  double next_log = start_time_ + 5.0;
  // The initial network (random, or the resumed one) goes out at once, so actors and tools see
  // weights flow. Versions are update counts, so a resumed learner's never go back.
  algorithm_->policy().GetFlat(&flat_);
  weights_.Start(algorithm_->updates(), algorithm_->policy().Architecture(), flat_);
  while (!StopRequested()) {
    if (config_.max_updates > 0 && algorithm_->updates() >= config_.max_updates) break;
    bus_->Handle(ready_.empty() && !weights_.busy() ? 2 : 0);
    const double now = MonoSeconds();
    TopUpRequests(now);
    if (!ready_.empty()) {
      TrainOn(ready_.front());
      spare_.push_back(std::move(ready_.front()));
      ready_.pop_front();
      TopUpRequests(now);
      const int64_t u = algorithm_->updates();
      if (u % config_.weights_every == 0) {
        algorithm_->policy().GetFlat(&flat_);
        weights_.Start(u, algorithm_->policy().Architecture(), flat_);
      }
      if (u % config_.checkpoint_every == 0) Checkpoint();
    }
    weights_.Tick();
    if (now >= next_stats) {
      PublishStats(now);
      next_stats = now + stats_period;
    }
    if (now >= next_log) {
      std::printf("learner: updates %lld env steps %lld timeouts %lld\n",
                  static_cast<long long>(algorithm_->updates()), static_cast<long long>(env_steps_),
                  static_cast<long long>(request_timeouts_));
      std::fflush(stdout);
      next_log = now + 5.0;
    }
  }
  if (algorithm_->updates() > 0) Checkpoint();
  PublishStats(MonoSeconds());
}

}  // namespace rl::learner
