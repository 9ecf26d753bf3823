#include "replay/replay_service.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>

#include "common/channels.h"
#include "common/check.h"
#include "replay/prioritized_sampler.h"
#include "replay/uniform_sampler.h"

namespace rl::replay {
namespace {

// Logs the first refusals and then every 1000th, so that a flood cannot flood the log.
bool ShouldLog(int64_t n) { return n < 10 || n % 1000 == 0; }

// Shortest readable form of a number, for error messages.
std::string Str(double x) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%g", x);
  return buf;
}

// Throws std::invalid_argument unless x is a finite rate > 0.
void CheckRate(const char* name, double x) {
  if (!std::isfinite(x) || x <= 0) {
    throw std::invalid_argument(std::string("replay service: ") + name + " must be > 0, got " +
                                Str(x));
  }
}

ReplayServiceOptions Validated(ReplayServiceOptions options) {
  options.Validate();
  return options;
}

}  // namespace

void ReplayServiceOptions::Validate() const {
  table.Validate();
  limiter.Validate();
  // Throws "replay service: <name> must be <rule>, got <value>" unless ok.
  const auto require = [](bool ok, const char* name, const char* rule, auto value) {
    if (ok) return;
    std::string got;
    if constexpr (std::is_integral_v<decltype(value)>) {
      got = std::to_string(value);
    } else {
      got = Str(value);
    }
    throw std::invalid_argument(std::string("replay service: ") + name + " must be " + rule +
                                ", got " + got);
  };
  require(insert_unit >= 1, "insert_unit", "at least 1", insert_unit);
  require(max_pending_requests >= 1, "max_pending_requests", "at least 1", max_pending_requests);
  require(max_reply_bytes >= 1024, "max_reply_bytes", "at least 1024", max_reply_bytes);
  CheckRate("flow_hz", flow_hz);
  CheckRate("stats_hz", stats_hz);
  require(std::isfinite(progress_seconds) && progress_seconds >= 0, "progress_seconds",
          ">= 0 (0: none)", progress_seconds);
  if (prioritized) {
    require(std::isfinite(alpha) && alpha >= 0, "alpha", ">= 0", alpha);
    require(std::isfinite(beta) && beta >= 0 && beta <= 1, "beta", "in [0, 1]", beta);
    require(std::isfinite(priority_epsilon) && priority_epsilon > 0, "priority_epsilon", "> 0",
            priority_epsilon);
  }
  require(beta_anneal_samples >= 0, "beta_anneal_samples", ">= 0", beta_anneal_samples);
  pixel_table().Validate();
  require(handle_timeout_ms >= 0, "handle_timeout_ms", ">= 0", handle_timeout_ms);
  require(max_actors >= 1 && max_actors <= kMaxActorsLimit, "max_actors", "in [1, 1024]",
          max_actors);
  require(stop_quiet_ms >= 0, "stop_quiet_ms", ">= 0", stop_quiet_ms);
  require(stop_drain_ms >= 0, "stop_drain_ms", ">= 0", stop_drain_ms);
}

PixelTableOptions ReplayServiceOptions::pixel_table() const {
  PixelTableOptions o;
  o.capacity = table.capacity;
  o.frame_capacity = frame_capacity;
  o.height = frames.height;
  o.width = frames.width;
  o.stack = frames.stack;
  o.action_width = table.action_width;
  return o;
}

TransitionBatchView ViewOf(const rlmsg::transition_batch_t& m) {
  return TransitionBatchView{
      .obs_size = m.obs_size,
      .count = m.count,
      .obs = m.obs,
      .next_obs = m.next_obs,
      .columns = {m.action_width, m.action, m.reward, m.discount, m.episode_id, m.priority},
      .actor_id = m.actor_id,
      .height = m.height,
      .width = m.width,
      .stack = m.stack,
      .num_frames = m.num_frames,
      .frame_id = m.frame_id,
      .frames = m.frames,
      .obs_frames = m.obs_frames,
      .next_obs_frames = m.next_obs_frames};
}

ReplayService::ReplayService(Bus* bus, ReplayServiceOptions options)
    : bus_(*bus),
      options_(Validated(std::move(options))),
      table_(MakeTable(options_.kind.value_or(TableKind::kFlat))),
      limiter_(options_.limiter),
      rng_(options_.seed) {
  insert_allowed_ = limiter_.CanInsert(options_.insert_unit);
  low_credit_ = limiter_.InsertCredit();
  bus_.Subscribe<rlmsg::transition_batch_t>(
      channels::kTransitions, [this](const rlmsg::transition_batch_t& m) { OnTransitions(m); });
  bus_.Subscribe<rlmsg::sample_request_t>(
      channels::kSampleRequest, [this](const rlmsg::sample_request_t& m) { OnSampleRequest(m); });
  bus_.Subscribe<rlmsg::priority_update_t>(
      channels::kPriorities, [this](const rlmsg::priority_update_t& m) { OnPriorities(m); });
}

std::unique_ptr<Sampler> ReplayService::MakeSampler() const {
  if (!options_.prioritized) return std::make_unique<UniformSampler>(options_.table.capacity);
  return std::make_unique<PrioritizedSampler>(options_.table.capacity, options_.alpha,
                                              options_.priority_epsilon);
}

std::unique_ptr<Table> ReplayService::MakeTable(TableKind kind) const {
  if (kind == TableKind::kPixels) {
    return std::make_unique<PixelTable>(options_.pixel_table(), MakeSampler());
  }
  return std::make_unique<ReplayTable>(options_.table, MakeSampler());
}

double ReplayService::beta() const {
  if (!options_.prioritized) return 1.0;
  if (options_.beta_anneal_samples <= 0) return options_.beta;
  const double progress = std::min(1.0, static_cast<double>(total_samples()) /
                                            static_cast<double>(options_.beta_anneal_samples));
  return options_.beta + (1.0 - options_.beta) * progress;
}

ReplayService::~ReplayService() = default;

void ReplayService::LogRefusal(const char* what, const char* why) {
  if (ShouldLog(refusals_logged_++)) {
    std::fprintf(stderr, "[%s] refused a %s: %s\n", bus_.config().sender.c_str(), what, why);
  }
}

void ReplayService::OnTransitions(const rlmsg::transition_batch_t& m) {
  // The bus has checked sizes and values; the env's action check comes next, then the table
  // checks what only it knows (observation size, geometry, action width, frame references).
  const char* why = nullptr;
  if (m.actor_id >= options_.max_actors) why = "actor_id not below max_actors";
  if (why == nullptr && options_.check_action) {
    const auto width = static_cast<size_t>(m.action_width);
    for (size_t i = 0; why == nullptr && i < static_cast<size_t>(m.count); ++i) {
      why = options_.check_action(std::span<const float>(m.action).subspan(i * width, width));
    }
  }
  const int64_t before = total_inserts();
  if (why == nullptr) why = Insert(m);
  if (why != nullptr) {
    ++counters_.batches_refused;
    LogRefusal("transition batch", why);
    return;
  }
  limiter_.Insert(total_inserts() - before);
  actor_inserts_[m.actor_id] += total_inserts() - before;
  PublishFlow(/*force=*/false);
}

const char* ReplayService::Insert(const rlmsg::transition_batch_t& m) {
  const TransitionBatchView batch = ViewOf(m);
  // Without a kind from the env's spec, the first batch decides: an unused table of the other
  // kind gives way.
  const TableKind kind = batch.obs_size > 0 ? TableKind::kFlat : TableKind::kPixels;
  if (!options_.kind && kind != table_->kind() && table_->unused()) table_ = MakeTable(kind);
  return table_->Insert(batch);
}

void ReplayService::OnPriorities(const rlmsg::priority_update_t& m) {
  const int64_t applied = table_->UpdatePriorities(m.index, m.priority);
  counters_.priorities_applied += applied;
  counters_.priorities_stale += m.count - applied;
}

void ReplayService::OnSampleRequest(const rlmsg::sample_request_t& m) {
  PendingRequest request{m.header.sender, m.request_id, m.batch_size};
  if (const char* why = Unanswerable(request)) {
    ++counters_.requests_refused;
    LogRefusal("sample request", why);
    return;
  }
  // A retried request that is still waiting here is held once, not twice.
  for (const PendingRequest& p : pending_) {
    if (p.request_id == request.request_id && p.requester == request.requester) return;
  }
  // Keep the newest requests: the requester has given up on the oldest by now.
  if (static_cast<int>(pending_.size()) >= options_.max_pending_requests) {
    pending_.pop_front();
    ++counters_.requests_dropped;
  }
  pending_.push_back(std::move(request));
}

const char* ReplayService::Unanswerable(const PendingRequest& request) {
  const int64_t max_batch = limiter_.max_sample_batch();
  if (max_batch > 0 && request.batch_size > max_batch) {
    return "batch_size above 2 * error_buffer - samples_per_insert (the limiter could never "
           "allow it)";
  }
  // The reply's size is known once the observations and the action width are.
  const ObservationShape shape = table_->shape();
  const int width = table_->action_width();
  if (width == 0 || !shape.known()) return nullptr;
  // The observation arrays alone, in 64 bits (also keeps the counts from overflowing).
  const int64_t obs_bytes = int64_t{shape.obs_size} * 4 + shape.pixel_bytes();
  if (int64_t{request.batch_size} * 2 * obs_bytes > options_.max_reply_bytes) {
    return "reply above max_reply_bytes";
  }
  // The exact encoded size: lcm-gen's size depends only on the counts and strings.
  rlmsg::sample_batch_t& r = reply_;
  r.header.sender = bus_.config().sender;
  r.requester = request.requester;
  r.count = request.batch_size;
  r.num_values = request.batch_size * shape.obs_size;
  r.num_bytes = static_cast<int32_t>(request.batch_size * shape.pixel_bytes());
  r.num_action_values = request.batch_size * width;
  if (r.getEncodedSize() > options_.max_reply_bytes) return "reply above max_reply_bytes";
  return nullptr;
}

int ReplayService::Serve() {
  int answered = 0;
  while (!pending_.empty()) {
    const PendingRequest& request = pending_.front();
    // Requests that arrived before the observation size was known are checked now.
    if (const char* why = Unanswerable(request)) {
      ++counters_.requests_refused;
      LogRefusal("sample request", why);
      pending_.pop_front();
      continue;
    }
    if (!limiter_.CanSample(request.batch_size)) break;
    Answer(request);
    pending_.pop_front();
    ++answered;
  }
  if (answered > 0) PublishFlow(/*force=*/false);
  return answered;
}

void ReplayService::Answer(const PendingRequest& request) {
  // Size the reused reply (no allocation once warm) and let the table fill it.
  const int count = request.batch_size;
  const auto n = static_cast<size_t>(count);
  rlmsg::sample_batch_t& r = reply_;
  r.requester = request.requester;
  r.request_id = request.request_id;
  r.count = count;
  const ObservationShape shape = table_->shape();
  r.obs_size = shape.obs_size;
  r.height = shape.height;
  r.width = shape.width;
  r.stack = shape.stack;
  r.num_values = count * shape.obs_size;
  r.num_bytes = static_cast<int32_t>(count * shape.pixel_bytes());
  r.action_width = table_->action_width();
  r.num_action_values = count * r.action_width;
  r.obs.resize(static_cast<size_t>(r.num_values));
  r.next_obs.resize(static_cast<size_t>(r.num_values));
  r.obs_pixels.resize(static_cast<size_t>(r.num_bytes));
  r.next_obs_pixels.resize(static_cast<size_t>(r.num_bytes));
  r.action.resize(static_cast<size_t>(r.num_action_values));
  r.reward.resize(n);
  r.discount.resize(n);
  r.index.resize(n);
  r.weight.resize(n);
  table_->set_importance_exponent(beta());
  const ColumnSpans columns{r.action, r.reward, r.discount, r.index, r.weight, {}};
  if (!table_->Sample(count, &rng_,
                      SampleSpans{r.obs, r.next_obs, columns, r.obs_pixels, r.next_obs_pixels})) {
    // CanSample() held, so transitions were stored; none can be drawn when each names an
    // overwritten frame (a frame ring far too small for the traffic) until new ones arrive.
    ++counters_.requests_refused;
    LogRefusal("sample request",
               "no stored transition can be drawn (each names an overwritten "
               "frame)");
    return;
  }
  r.replay_size = table_->size();
  r.total_inserts = table_->total_inserts();
  limiter_.Sample(count);
  bus_.Publish(channels::kSamples, &r, Port::kSamples);
  ++counters_.requests_answered;
}

void ReplayService::PublishFlow(bool force) {
  const bool allowed = limiter_.CanInsert(options_.insert_unit);
  const int64_t credit = allowed ? limiter_.InsertCredit() : 0;
  // The credit's range: from 0 to 2 * error_buffer / SPI once sampling runs.
  const RateLimiterOptions& o = limiter_.options();
  const double range = o.samples_per_insert > 0 ? 2 * o.error_buffer / o.samples_per_insert : 0;
  low_credit_ = std::min(low_credit_, credit);
  const bool grew =
      credit >= 0 && static_cast<double>(credit - low_credit_) >= std::max(1.0, range / 4);
  if (!force && allowed == insert_allowed_ && !grew) return;
  insert_allowed_ = allowed;
  low_credit_ = credit;
  flow_.insert_allowed = allowed ? 1 : 0;
  flow_.samples_per_insert = limiter_.samples_per_insert();
  flow_.target_samples_per_insert = o.samples_per_insert;
  flow_.error_buffer = o.error_buffer;
  flow_.insert_credit = credit;
  flow_.num_actors = static_cast<int32_t>(actor_inserts_.size());
  flow_.actor_id.clear();
  flow_.actor_inserts.clear();
  for (const auto& [id, n] : actor_inserts_) {
    flow_.actor_id.push_back(id);
    flow_.actor_inserts.push_back(n);
  }
  bus_.Publish(channels::kFlow, &flow_);
}

void ReplayService::PublishStats(double now) {
  stats_.size = size();
  stats_.capacity = table_->capacity();
  stats_.total_inserts = total_inserts();
  stats_.total_samples = total_samples();
  stats_.inserts_per_second = stats_insert_rate_.Take(total_inserts(), now);
  stats_.samples_per_second = stats_sample_rate_.Take(total_samples(), now);
  stats_.prioritized = options_.prioritized ? 1 : 0;
  stats_.beta = beta();
  stats_.memory_bytes = memory_bytes();
  stats_.frames = std::min(table_->total_frames(), table_->frame_capacity());
  stats_.priorities_applied = counters_.priorities_applied;
  stats_.priorities_stale = counters_.priorities_stale;
  stats_.missing_frames = table_->transitions_missing_frames();
  stats_.stale_draws = table_->stale_draws();
  stats_.samples_per_insert = limiter_.samples_per_insert();
  stats_.insert_allowed = insert_allowed_ ? 1 : 0;
  stats_.pending_requests = pending_requests();
  bus_.FillCounters(&stats_);
  // What the service refused itself is invalid input as well.
  stats_.dropped_invalid += counters_.batches_refused + counters_.requests_refused;
  bus_.Publish(channels::kStatsReplay, &stats_);
}

void ReplayService::PrintProgress(double now) {
  const double inserts_per_second = progress_insert_rate_.Take(total_inserts(), now);
  const double samples_per_second = progress_sample_rate_.Take(total_samples(), now);
  const BusCounters& bus = bus_.counters();
  std::printf(
      "replay: size %lld/%lld inserts %lld (%.1f/s) samples %lld (%.1f/s) spi %.2f "
      "insert_allowed %d pending %d dropped %lld lost %lld memory %.1f MB",
      static_cast<long long>(size()), static_cast<long long>(table_->capacity()),
      static_cast<long long>(total_inserts()), inserts_per_second,
      static_cast<long long>(total_samples()), samples_per_second, limiter_.samples_per_insert(),
      insert_allowed_ ? 1 : 0, pending_requests(),
      static_cast<long long>(bus.dropped()) + counters_.batches_refused +
          counters_.requests_refused + counters_.requests_dropped,
      static_cast<long long>(bus.lost), static_cast<double>(memory_bytes()) / 1e6);
  if (options_.prioritized) {
    std::printf(" beta %.3f priorities %lld stale %lld", beta(),
                static_cast<long long>(counters_.priorities_applied),
                static_cast<long long>(counters_.priorities_stale));
  }
  // Tables that store frames.
  if (table_->frame_capacity() > 0) {
    std::printf(" frames %lld missing_frames %lld stale_draws %lld",
                static_cast<long long>(table_->total_frames()),
                static_cast<long long>(table_->transitions_missing_frames()),
                static_cast<long long>(table_->stale_draws()));
  }
  std::printf("\n");
  std::fflush(stdout);
}

void ReplayService::Tick(double now) {
  // Each publication is due once its period has passed; a late tick does not cause a burst.
  if (now >= next_flow_) {
    PublishFlow(/*force=*/true);
    next_flow_ = now + 1.0 / options_.flow_hz;
  }
  if (now >= next_stats_) {
    PublishStats(now);
    next_stats_ = now + 1.0 / options_.stats_hz;
  }
  if (options_.progress_seconds > 0 && now >= next_progress_) {
    // The first call only starts the rate intervals.
    if (next_progress_ >= 0) {
      PrintProgress(now);
    } else {
      progress_insert_rate_.Take(total_inserts(), now);
      progress_sample_rate_.Take(total_samples(), now);
    }
    next_progress_ = now + options_.progress_seconds;
  }
}

void ReplayService::Run(const std::function<bool()>& should_stop) {
  while (!should_stop()) {
    bus_.Handle(options_.handle_timeout_ms);
    Serve();
    Tick();
  }
  // The actors stop at the same time and send their last steps: store them too, so that the
  // last snapshot holds every step of theirs (a restarted actor takes its count from it).
  const double drain_end = MonoSeconds() + options_.stop_drain_ms / 1000.0;
  while (MonoSeconds() < drain_end && bus_.Handle(options_.stop_quiet_ms) > 0) {
  }
  // Leave a last word for the monitor, and the final counts in the log.
  const double now = MonoSeconds();
  PublishFlow(/*force=*/true);
  PublishStats(now);
  if (options_.progress_seconds > 0) PrintProgress(now);
}

}  // namespace rl::replay
