// ReplayService: the replay daemon's LCM side. It connects a Table (table.h) and a RateLimiter
// to the bus.
//
// In (main port):
//   RL_TRANSITIONS     transition_batch_t  every valid batch is stored, whatever the limiter says
//                                          (the limiter only tells actors to pause): flat ones
//                                          in a ReplayTable, pixel ones (frames stored once) in
//                                          a PixelTable
//   RL_SAMPLE_REQUEST  sample_request_t    queued; several may be in flight
//   RL_PRIORITIES      priority_update_t   new priorities (prioritized replay)
// Out:
//   RL_SAMPLES         sample_batch_t      (samples port) one reply per request, in request order,
//                                          as soon as the limiter allows a sample of its size
//                                          (flat observations or rebuilt pixel stacks)
//   RL_FLOW            flow_control_t      at flow_hz, and at once whenever insert_allowed changes
//   RL_STATS_REPLAY    stats_replay_t      at stats_hz
//
// What the bus drops (malformed, foreign, invalid, lost) is counted by the bus; what the service
// itself refuses (a batch the table will not store, a request that can never be answered) is
// counted here and reported in stats_replay_t.dropped_invalid together with the bus's count.
//
// A run stores either flat or pixel transitions, in the table of that kind: the env's static
// spec says which (options.kind), or else the kind of the first batch; batches of the other kind
// are refused. Actions are stored as the env's action width of floats
// and are otherwise opaque to the replay; an optional check (from the env's static spec: width,
// integer indices, bounds) refuses a whole batch with a bad action. Sampling is uniform, or
// proportional to priority (Schaul et al. 2016) with importance weights whose exponent beta is
// annealed to 1.
//
// Replies are one message each: a request whose reply would exceed max_reply_bytes is refused.
// For CartPole a batch of 128 is about 7 KB; a batch of 32 Nature-DQN stacks (4 x 84 x 84) about
// 1.8 MB.
//
// Snapshots (replay_service_snapshot.cc): SaveSnapshot() describes the whole state a restarted
// replay needs to serve as before (the table with its sampler, the limiter's counts, the
// sampler's random generator, the per-actor insert counts, the service's counters, the bus's
// last position of each sender, so that recorded traffic older than the snapshot stays refused;
// not the pending requests, which their requesters send again) as a StateStream of kind
// kSnapshotKind; RestoreSnapshot()/LoadSnapshot() load one into a fresh service.
//
// Not thread-safe: one thread constructs the service and calls every method; the bus must be
// used by that thread only and must outlive the service.
#pragma once

#include <cstdint>
#include <deque>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <random>
#include <span>
#include <string>

#include "common/clock.h"
#include "common/lcm_bus.h"
#include "common/state_file.h"
#include "replay/pixel_table.h"
#include "replay/rate_limiter.h"
#include "replay/replay_table.h"
#include "replay/table.h"
#include "rlmsg/flow_control_t.hpp"
#include "rlmsg/priority_update_t.hpp"
#include "rlmsg/sample_batch_t.hpp"
#include "rlmsg/sample_request_t.hpp"
#include "rlmsg/stats_replay_t.hpp"
#include "rlmsg/transition_batch_t.hpp"

namespace rl::replay {

/// The largest max_actors: the pixel table holds the frame windows of 1024 actors at most.
inline constexpr int kMaxActorsLimit = 1024;

struct ReplayServiceOptions {
  // Storage: capacity, and the observation size of flat transitions (0: from the first batch).
  ReplayTableOptions table;
  // The kind of table, from the env's static spec (flat, or pixels when the env gives frames);
  // none: the kind of the first batch.
  std::optional<TableKind> kind;
  // Pixel tables: the frames' height, width and stack (0: from the first batch).
  ObservationShape frames;
  // Samples-per-insert ratio, minimum size and tolerance.
  RateLimiterOptions limiter;
  // Seed of the sampler's random generator.
  uint64_t seed = 1;
  // Prioritized sampling: P(i) proportional to (priority_i + priority_epsilon)^alpha, importance
  // weights (N P(i))^-beta normalised by their maximum, beta growing linearly from `beta` to 1
  // over the first beta_anneal_samples sampled transitions (0: constant).
  bool prioritized = false;
  double alpha = 0.6;
  double beta = 0.4;
  int64_t beta_anneal_samples = 0;
  double priority_epsilon = 1e-6;
  // Frames kept for pixel transitions (0: the pixel table's default, a little above capacity).
  int64_t frame_capacity = 0;
  // Why an action (action width floats) is not one of the run's env, or nullptr; empty: no check
  // (the width is then fixed by the first batch). A batch with any bad action is refused whole.
  std::function<const char*(std::span<const float>)> check_action;
  // Transitions an actor asks to insert at a time: insert_allowed is CanInsert(insert_unit).
  int insert_unit = 1;
  // Sample requests waiting for the limiter; when full, the oldest is dropped.
  int max_pending_requests = 64;
  // Largest reply (encoded bytes); larger requests are refused. The default fits twice into the
  // 8 MiB receive buffers of our URLs.
  int64_t max_reply_bytes = 4 << 20;
  // Periodic flow_control_t publications per second (changes are published at once as well).
  double flow_hz = 20.0;
  // stats_replay_t publications per second.
  double stats_hz = 4.0;
  // Seconds between progress lines on stdout (size, rates); 0: none.
  double progress_seconds = 0.0;
  // Milliseconds Run() waits for traffic in each round.
  int handle_timeout_ms = 10;
  // Actor ids stored: 0 .. max_actors - 1. A batch of another id is refused and counted, so that
  // forged ids cannot grow the per-actor counts (and the flow messages and snapshots that carry
  // them) without bound. At most kMaxActorsLimit.
  int max_actors = 1024;
  // When Run() is asked to stop, it goes on storing what arrives until nothing has for
  // stop_quiet_ms (at most stop_drain_ms in all): the last batches of actors that stop at the
  // same time (they flush their last steps) reach the last snapshot.
  int stop_quiet_ms = 100;
  int stop_drain_ms = 1000;

  /// Throws std::invalid_argument naming the field when a value is out of range.
  void Validate() const;
  /// The options of the pixel table: capacity, frame capacity, geometry, action width.
  PixelTableOptions pixel_table() const;
};

/// What the service refused or dropped itself (the bus counts the rest).
struct ServiceCounters {
  int64_t batches_refused = 0;     // transition batches the table would not store
  int64_t requests_refused = 0;    // requests whose batch could never be served
  int64_t requests_dropped = 0;    // pending requests pushed out of a full queue
  int64_t requests_answered = 0;   // replies published
  int64_t priorities_applied = 0;  // priority updates applied
  int64_t priorities_stale = 0;    // priority updates for transitions overwritten since
};

/// The batch of a transition_batch_t, as views of its arrays.
TransitionBatchView ViewOf(const rlmsg::transition_batch_t& m);

class ReplayService {
 public:
  /// Subscribes to RL_TRANSITIONS and RL_SAMPLE_REQUEST on `bus`. Throws std::invalid_argument
  /// when the options are bad.
  ReplayService(Bus* bus, ReplayServiceOptions options);
  ReplayService(const ReplayService&) = delete;
  ReplayService& operator=(const ReplayService&) = delete;
  ~ReplayService();

  /// Answers pending requests, oldest first, while the limiter allows the oldest one's batch.
  /// Returns the number of replies published.
  int Serve();

  /// Time-driven work: periodic flow control, stats and progress lines when due. `now` is in
  /// seconds on the monotonic clock (MonoSeconds()).
  void Tick(double now);
  void Tick() { Tick(MonoSeconds()); }

  /// Handles traffic, serves and ticks until should_stop() returns true (checked before each
  /// round), then stores what still arrives (options: stop_quiet_ms, stop_drain_ms). Publishes
  /// a flow_control_t and a stats_replay_t before returning.
  void Run(const std::function<bool()>& should_stop);

  /// The table that holds the run's transitions.
  const Table& table() const { return *table_; }
  int64_t size() const { return table_->size(); }
  int64_t total_inserts() const { return table_->total_inserts(); }
  int64_t total_samples() const { return table_->total_samples(); }
  /// Bytes held by the table and its sampler.
  int64_t memory_bytes() const { return table_->memory_bytes(); }
  /// Importance-sampling exponent for the next batch (1 when sampling is uniform).
  double beta() const;
  const RateLimiter& limiter() const { return limiter_; }
  const ServiceCounters& counters() const { return counters_; }
  int pending_requests() const { return static_cast<int>(pending_.size()); }
  /// Last value of insert_allowed published on RL_FLOW.
  bool insert_allowed() const { return insert_allowed_; }

  /// The state file kind of a replay snapshot.
  static constexpr const char* kSnapshotKind = "replay snapshot";
  /// Adds the service's whole state to `out` (a StateStream of kSnapshotKind), referring to the
  /// tables' arrays: nothing may change until the snapshot is written (a fork()ed child writes a
  /// copy-on-write image). Returns a one-line summary ("size N, inserts N, samples N"). O(actors)
  /// and a copy of the generator's state (about 6 KB); the arrays are not copied.
  std::string SaveSnapshot(StateStream* out) const;
  /// Loads a snapshot into this service, which must be fresh (nothing inserted, sampled or
  /// requested: std::logic_error otherwise). Throws std::runtime_error saying why the snapshot is
  /// refused: not a replay snapshot (bad magic, another kind), torn or corrupted (checksum), of
  /// another run id, of another table (flat or pixels, capacity, frame capacity, shapes,
  /// uniform or prioritized, alpha, epsilon), or with contents that are not a replay's. Never
  /// crashes on any bytes; allocates only what the configuration and lengths checked against
  /// it call for. A service whose restore threw must be discarded. Returns the summary.
  std::string RestoreSnapshot(std::string_view bytes);
  /// Maps the file at `path` and restores it; errors are "state <path> refused: <why>" (or
  /// "cannot read state <path>: <why>").
  std::string LoadSnapshot(const std::string& path);

 private:
  struct PendingRequest {
    std::string requester;
    int64_t request_id = 0;
    int32_t batch_size = 0;
  };

  void OnTransitions(const rlmsg::transition_batch_t& m);
  // Stores the batch; the reason it was refused, or nullptr.
  const char* Insert(const rlmsg::transition_batch_t& m);
  void OnSampleRequest(const rlmsg::sample_request_t& m);
  void OnPriorities(const rlmsg::priority_update_t& m);
  std::unique_ptr<Sampler> MakeSampler() const;
  // An empty table of `kind`, as the options configure it.
  std::unique_ptr<Table> MakeTable(TableKind kind) const;
  void CheckFresh() const;
  void Restore(const StateView& in);
  // The table's part of Restore(): a table of the snapshot's kind, unless the env says another.
  void RestoreTable(const StateView& in);
  std::string Summary() const;
  // Draws and publishes the reply to one request.
  void Answer(const PendingRequest& request);
  // Why a request can never be answered, or nullptr.
  const char* Unanswerable(const PendingRequest& request);
  // Publishes flow_control_t when `force`, when insert_allowed changes, or when the credit has
  // grown by a quarter of its range above its lowest since the last publication (so that actors
  // waiting for credit hear of it soon).
  void PublishFlow(bool force);
  void PublishStats(double now);
  void PrintProgress(double now);
  void LogRefusal(const char* what, const char* why);

  Bus& bus_;
  ReplayServiceOptions options_;
  std::unique_ptr<Table> table_;
  RateLimiter limiter_;
  std::mt19937_64 rng_;
  std::deque<PendingRequest> pending_;
  ServiceCounters counters_;
  bool insert_allowed_ = true;
  // The lowest insert credit since the last flow message (which resets it to its credit).
  int64_t low_credit_ = 0;
  // Transitions stored from each actor (by actor_id), for the flow messages.
  std::map<int32_t, int64_t> actor_inserts_;
  int64_t refusals_logged_ = 0;

  // Next due times of the periodic publications (monotonic seconds; < 0: at the next Tick).
  double next_flow_ = -1.0;
  double next_stats_ = -1.0;
  double next_progress_ = -1.0;
  RateMeter stats_insert_rate_;
  RateMeter stats_sample_rate_;
  RateMeter progress_insert_rate_;
  RateMeter progress_sample_rate_;

  // Reused messages, so that a warm service does not allocate per reply.
  rlmsg::sample_batch_t reply_{};
  rlmsg::flow_control_t flow_{};
  rlmsg::stats_replay_t stats_{};
};

}  // namespace rl::replay
