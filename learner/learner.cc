#include "learner/learner.h"

#include <cstdio>
#include <filesystem>
#include <stdexcept>
#include <type_traits>

#include "common/channels.h"
#include "common/clock.h"
#include "common/shutdown.h"
#include "envs/registry.h"
#include "nn/checkpoint.h"
#include "nn/parallel.h"
#include "rlmsg/checkpoint_t.hpp"
#include "rlmsg/sample_request_t.hpp"
#include "rlmsg/stats_learner_t.hpp"

namespace rl::learner {
namespace {

int ObsSize(const std::string& env_id, int augment_shift) {
  const envs::EnvSpec spec = envs::MakeEnv(env_id)->spec();
  if (augment_shift > 0 && spec.frame_height <= 0) {
    throw std::invalid_argument("augment-shift applies to pixel envs, and " + env_id +
                                " is not one");
  }
  return spec.observation_size;
}
int NumActions(const std::string& env_id) { return envs::MakeEnv(env_id)->spec().num_actions; }

}  // namespace

void LearnerConfig::Validate() const {
  dqn.Validate();
  if (batch_size < 1 || batch_size > 65536) throw std::invalid_argument("batch-size in [1, 65536]");
  if (requests_in_flight < 1) throw std::invalid_argument("requests-in-flight must be >= 1");
  if (!(request_timeout > 0)) throw std::invalid_argument("request-timeout must be > 0");
  if (weights_every < 1) throw std::invalid_argument("weights-every must be >= 1");
  if (checkpoint_every < 1) throw std::invalid_argument("checkpoint-every must be >= 1");
  if (keep_checkpoints < 0) throw std::invalid_argument("keep-checkpoints must be >= 0");
  if (!(stats_hz > 0)) throw std::invalid_argument("stats-hz must be > 0");
  if (threads < 1 || threads > 64) throw std::invalid_argument("threads must be in [1, 64]");
}

Learner::Learner(LearnerConfig config, Bus* bus)
    : config_((config.Validate(), std::move(config))),
      bus_(bus),
      obs_size_(ObsSize(config_.env_id, config_.dqn.augment_shift)),
      dqn_(obs_size_, NumActions(config_.env_id), config_.dqn),
      weights_(bus),
      sender_(bus->config().sender) {
  nn::SetNumThreads(config_.threads);
  std::filesystem::create_directories(std::filesystem::path(config_.out_dir) / "checkpoints");
  bus_->Subscribe<rlmsg::sample_batch_t>(
      channels::kSamples, [this](const rlmsg::sample_batch_t& m) { OnSamples(m); }, Port::kBulk);
  bus_->Subscribe<rlmsg::pixel_sample_batch_t>(
      channels::kPixelSamples, [this](const rlmsg::pixel_sample_batch_t& m) { OnPixelSamples(m); },
      Port::kBulk);
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

void Learner::OnSamples(const rlmsg::sample_batch_t& m) {
  if (!Accept(m.requester, m.request_id, m.total_inserts)) return;
  if (m.obs_size != obs_size_) {
    throw std::invalid_argument("sample batch with observation size " + std::to_string(m.obs_size) +
                                ", expected " + std::to_string(obs_size_));
  }
  ready_.emplace_back(m);
}

void Learner::OnPixelSamples(const rlmsg::pixel_sample_batch_t& m) {
  if (!Accept(m.requester, m.request_id, m.total_inserts)) return;
  const int64_t obs_size = int64_t{m.stack} * m.height * m.width;
  if (obs_size != obs_size_) {
    throw std::invalid_argument("pixel sample batch of " + std::to_string(m.stack) + " x " +
                                std::to_string(m.height) + " x " + std::to_string(m.width) +
                                " bytes per observation, expected " + std::to_string(obs_size_));
  }
  ready_.emplace_back(m);
}

void Learner::PublishPriorities(const std::vector<int64_t>& index) {
  const std::vector<float>& td = dqn_.last_td_errors();
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

void Learner::TrainOn(const Batch& batch) {
  BatchView b;
  b.obs_size = obs_size_;
  const std::vector<int64_t>* index = nullptr;
  std::visit(
      [&](const auto& m) {
        b.count = m.count;
        if constexpr (std::is_same_v<std::decay_t<decltype(m)>, rlmsg::sample_batch_t>) {
          b.obs = m.obs.data();
          b.next_obs = m.next_obs.data();
        } else {
          b.obs_pixels = m.obs.data();
          b.next_obs_pixels = m.next_obs.data();
          b.frame_height = m.height;
          b.frame_width = m.width;
        }
        b.action = m.action.data();
        b.reward = m.reward.data();
        b.discount = m.discount.data();
        b.weight = m.weight.data();
        index = &m.index;
      },
      batch);
  const UpdateResult r = dqn_.Update(b);
  if (config_.prioritized) PublishPriorities(*index);
  loss_sum_ += r.loss;
  q_sum_ += r.mean_q;
  ++stat_updates_;
}

std::string Learner::Checkpoint() {
  char name[64];
  std::snprintf(name, sizeof(name), "ckpt-%09lld.bin", static_cast<long long>(dqn_.updates()));
  const std::string path = (std::filesystem::path(config_.out_dir) / "checkpoints" / name).string();
  nn::Checkpoint ckpt;
  ckpt.architecture = dqn_.online().Architecture();
  ckpt.meta.update = dqn_.updates();
  ckpt.meta.env_steps = env_steps_;
  ckpt.meta.wall_seconds = MonoSeconds() - start_time_;
  ckpt.meta.run_id = static_cast<uint64_t>(bus_->config().run_id);
  ckpt.meta.note = config_.env_id;
  dqn_.online().GetFlat(&ckpt.params);
  nn::SaveCheckpoint(path, ckpt);
  // Keep the newest keep_checkpoints files; older ones have been scored or skipped by now.
  if (written_.empty() || written_.back() != path) written_.push_back(path);
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
  s.updates = dqn_.updates();
  const double dt = now - stats_last_time_;
  s.updates_per_second = (stats_last_time_ > 0 && dt > 0)
                             ? static_cast<double>(s.updates - stats_last_updates_) / dt
                             : 0.0;
  s.samples_per_second = s.updates_per_second * config_.batch_size;
  s.loss = stat_updates_ > 0 ? loss_sum_ / static_cast<double>(stat_updates_) : 0.0;
  s.mean_q = stat_updates_ > 0 ? q_sum_ / static_cast<double>(stat_updates_) : 0.0;
  s.weights_version = weights_.published_version();
  s.env_steps = env_steps_;
  s.request_timeouts = request_timeouts_;
  s.priorities_sent = priorities_sent_;
  bus_->FillCounters(&s);
  bus_->Publish(channels::kStatsLearner, &s);
  stats_last_time_ = now;
  stats_last_updates_ = s.updates;
  loss_sum_ = q_sum_ = 0;
  stat_updates_ = 0;
}

void Learner::Run() {
  start_time_ = MonoSeconds();
  const double stats_period = 1.0 / config_.stats_hz;
  double next_stats = start_time_;
  double next_log = start_time_ + 5.0;
  // The initial (random) network goes out at once, so actors and tools see weights flow.
  dqn_.online().GetFlat(&flat_);
  weights_.Start(0, dqn_.online().Architecture(), flat_);
  while (!StopRequested()) {
    if (config_.max_updates > 0 && dqn_.updates() >= config_.max_updates) break;
    bus_->Handle(ready_.empty() && !weights_.busy() ? 2 : 0);
    const double now = MonoSeconds();
    TopUpRequests(now);
    if (!ready_.empty()) {
      TrainOn(ready_.front());
      ready_.pop_front();
      TopUpRequests(now);
      const int64_t u = dqn_.updates();
      if (u % config_.weights_every == 0) {
        dqn_.online().GetFlat(&flat_);
        weights_.Start(u, dqn_.online().Architecture(), flat_);
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
                  static_cast<long long>(dqn_.updates()), static_cast<long long>(env_steps_),
                  static_cast<long long>(request_timeouts_));
      std::fflush(stdout);
      next_log = now + 5.0;
    }
  }
  if (dqn_.updates() > 0) Checkpoint();
  PublishStats(MonoSeconds());
}

}  // namespace rl::learner
