// One publisher of the transport benchmark (bench/transport.sh): an "actor" process that
// publishes transition batches to a real replay daemon (build/bin/replay) over real LCM, udpm or
// tcpq, as fast as the replay's flow control allows, and reports what the replay stored of them.
//
// It waits for the replay's first RL_FLOW message (its readiness), then until the wall-clock
// time --start-at (so that the publishers of one measurement start together, on any node), then
// publishes back to back for --seconds, under the flow control an actor obeys (actor/actor.cc):
// only while insert_allowed, and no more than its share of the insert credit less what it has
// published that is not stored yet (a replay without a ratio, --samples-per-insert 0, gives no
// credit limit: the raw limit of the transport and the replay); with --window N, also no more
// than N transitions published and not yet stored (a fixed share, as a replay with a ratio gives
// each actor: nothing is lost while N fits in the receive buffers). Then it waits until the replay
// has stored all it published, or until its flow messages have shown no growth for --settle
// seconds, and prints one JSON line:
//   published, messages, bytes     what it published (transitions, batches, encoded bytes)
//   publish_failed                 publications LCM reported as failed
//   stored                         what the replay stored of them (RL_FLOW's count for its id)
//   start, end, last_stored        wall-clock seconds: publishing began, ended, and the arrival
//                                  of the flow message that showed the last growth of the stored
//                                  count (so stored / (last_stored - start) is the rate the
//                                  replay took them in, or a little less)
//   paused_s                       seconds the flow control held it back
//   replay_lost, replay_missing_frames, replay_dropped
//                                  the growth of the replay's counts over the measurement (every
//                                  publisher's, RL_STATS_REPLAY): messages lost on the way
//                                  (sequence gaps), pixel transitions skipped for a lost frame,
//                                  messages dropped (malformed, unauthenticated, ...)
//
// Flat batches are 32 CartPole-size transitions (bench/transition_batches.h); pixel batches are
// 32 transitions with their new 84 x 84 frames, stacks of 4 (about 230 KB).
//
// Usage: bench_transport --kind flat|pixel --actor-id I --actors N --seconds S --start-at T
//                        --run-id R --lcm-url U --lcm-bulk-url B [--key-file F] [--window N]
#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <memory>
#include <string>

#include "bench/transition_batches.h"
#include "common/channels.h"
#include "common/clock.h"
#include "common/lcm_bus.h"
#include "common/options.h"
#include "rlmsg/flow_control_t.hpp"
#include "rlmsg/stats_replay_t.hpp"

namespace {

constexpr char kUsage[] =
    "Usage: bench_transport --kind flat|pixel --actor-id I --actors N --seconds S --start-at T\n"
    "                       [--run-id R --lcm-url U --lcm-bulk-url B --key-file F --window N]\n"
    "One publisher of bench/transport.sh: publishes transition batches (flat CartPole-size, or\n"
    "84x84x4 pixel ones) to a running replay daemon as fast as its flow control allows, from the\n"
    "wall-clock time T (seconds since the epoch) for S seconds, then prints one JSON line with\n"
    "what it published and what the replay stored of it.";

// What the replay tells this publisher: its flow control and its counts.
struct ReplayView {
  int32_t actor_id = 0;
  int64_t actors = 1;
  bool heard = false;          // a flow message has come
  bool insert_allowed = true;  // the last flow message's
  int64_t credit = -1;         // the last flow message's insert credit (-1: no limit)
  int64_t stored = 0;          // transitions of this actor id the replay has stored
  double stored_changed = 0;   // wall-clock seconds of the last growth of `stored`
  double last_flow = 0;        // wall-clock seconds of the last flow message
  bool stats_heard = false;
  int64_t lost = 0, missing_frames = 0, dropped = 0;  // the replay's counts, every sender's

  void OnFlow(const rlmsg::flow_control_t& f) {
    heard = true;
    last_flow = 1e-6 * static_cast<double>(rl::WallMicros());
    insert_allowed = f.insert_allowed != 0;
    credit = f.insert_credit;
    for (size_t i = 0; i < f.actor_id.size(); ++i) {
      if (f.actor_id[i] == actor_id && f.actor_inserts[i] != stored) {
        stored = f.actor_inserts[i];
        stored_changed = 1e-6 * static_cast<double>(rl::WallMicros());
      }
    }
  }
  void OnStats(const rlmsg::stats_replay_t& s) {
    stats_heard = true;
    lost = s.lost;
    missing_frames = s.missing_frames;
    dropped = s.dropped_malformed + s.dropped_foreign + s.dropped_invalid +
              s.dropped_unauthenticated + s.dropped_stale + s.dropped_replayed;
  }
  // How many transitions this actor may have published in all now (actor/actor.cc's rule, with
  // at most `window` on the way when window > 0).
  int64_t Limit(int64_t published, int64_t stored_at_start, int64_t window) const {
    if (!insert_allowed) return published;
    const int64_t on_the_way = std::max<int64_t>(0, published - (stored - stored_at_start));
    int64_t share =
        credit < 0 ? std::numeric_limits<int64_t>::max() / 2 : (credit + actors - 1) / actors;
    if (window > 0) share = std::min(share, window);
    return published + std::max<int64_t>(0, share - on_the_way);
  }
};

double WallSeconds() { return 1e-6 * static_cast<double>(rl::WallMicros()); }

// Handles the bus until `done()` or `limit` wall-clock seconds; false at the limit.
template <class Done>
bool HandleUntil(rl::Bus* bus, double limit, Done done) {
  while (!done()) {
    if (WallSeconds() >= limit) return false;
    bus->Handle(5);
  }
  return true;
}

int Main(int argc, char** argv) {
  rl::CommonOptions common;
  std::string kind = "flat";
  int32_t actor_id = 0;
  int64_t actors = 1, window = 0;
  double seconds = 2.0, start_at = 0, settle = 1.0, ready_timeout = 30.0;
  rl::po::options_description desc("Options");
  rl::AddCommonOptions(&desc, &common);
  desc.add_options()                                                                         //
      ("kind", rl::po::value(&kind)->default_value(kind), "flat or pixel transitions")       //
      ("actor-id", rl::po::value(&actor_id)->default_value(actor_id), "actor id published")  //
      ("actors", rl::po::value(&actors)->default_value(actors),
       "publishers sharing the replay's insert credit")                                      //
      ("seconds", rl::po::value(&seconds)->default_value(seconds), "seconds of publishing")  //
      ("start-at", rl::po::value(&start_at)->default_value(start_at),
       "wall-clock time to start publishing, seconds since the epoch (0: at once)")  //
      ("settle", rl::po::value(&settle)->default_value(settle),
       "seconds of flow messages without a new stored transition that end the wait for the "
       "replay")  //
      ("window", rl::po::value(&window)->default_value(window),
       "transitions published and not yet stored at most (0: only the replay's flow control)")  //
      ("ready-timeout", rl::po::value(&ready_timeout)->default_value(ready_timeout),
       "seconds to wait for the replay's first flow message");
  rl::po::variables_map vm;
  if (!rl::ParseOptions(argc, argv, "actor", kUsage, desc, &vm)) return 0;
  if (kind != "flat" && kind != "pixel")
    throw std::invalid_argument("--kind must be flat or pixel");
  if (!(seconds > 0) || actors < 1 || actor_id < 0 || !(settle > 0) || window < 0) {
    throw std::invalid_argument(
        "--seconds and --settle must be > 0, --actors >= 1, --actor-id and --window >= 0");
  }

  rl::Bus bus(common.MakeBusConfig("actor-" + std::to_string(actor_id)));
  ReplayView replay;
  replay.actor_id = actor_id;
  replay.actors = actors;
  bus.Subscribe<rlmsg::flow_control_t>(
      rl::channels::kFlow, [&replay](const rlmsg::flow_control_t& f) { replay.OnFlow(f); });
  bus.Subscribe<rlmsg::stats_replay_t>(
      rl::channels::kStatsReplay, [&replay](const rlmsg::stats_replay_t& s) { replay.OnStats(s); });
  if (!HandleUntil(&bus, WallSeconds() + ready_timeout,
                   [&] { return replay.heard && replay.stats_heard; })) {
    throw std::runtime_error("no flow control and stats from the replay within " +
                             std::to_string(ready_timeout) + " s");
  }
  HandleUntil(&bus, start_at, [] { return false; });

  const int64_t stored_at_start = replay.stored;
  const int64_t lost_at_start = replay.lost, missing_at_start = replay.missing_frames,
                dropped_at_start = replay.dropped;
  std::unique_ptr<rl::bench::PixelActorSim> sim;
  if (kind == "pixel") sim = std::make_unique<rl::bench::PixelActorSim>(actor_id, 1000 + actor_id);
  rlmsg::transition_batch_t flat = rl::bench::FlatBatch();
  flat.actor_id = actor_id;
  int64_t published = 0, messages = 0, bytes = 0, failed = 0;
  double paused = 0;
  const double start = WallSeconds();
  double now = start;
  while (now - start < seconds) {
    if (published + rl::bench::kBatch <= replay.Limit(published, stored_at_start, window)) {
      rlmsg::transition_batch_t* batch = sim ? sim->Next() : &flat;
      if (!bus.Publish(rl::channels::kTransitions, batch)) ++failed;
      published += batch->count;
      bytes += batch->getEncodedSize();
      ++messages;
      bus.Handle(0);
    } else {
      bus.Handle(1);
      paused += WallSeconds() - now;
    }
    now = WallSeconds();
  }
  const double end = now;
  // Until everything is stored, or the flow messages have shown no more for `settle` seconds
  // (the rest is lost). A replay draining a backlog publishes no flow message until it is
  // through (one Handle() call takes every message waiting), so silence is not an answer; at most
  // kMaxSettle seconds in all.
  constexpr double kMaxSettle = 60;
  while (replay.stored - stored_at_start < published &&
         replay.last_flow - std::max(replay.stored_changed, end) < settle &&
         WallSeconds() - end < kMaxSettle) {
    bus.Handle(5);
  }
  // The replay's next stats message, so that its counts include this publisher's last batches.
  replay.stats_heard = false;
  HandleUntil(&bus, WallSeconds() + 2, [&] { return replay.stats_heard; });
  std::printf(
      "{\"kind\": \"%s\", \"actor_id\": %d, \"published\": %lld, \"messages\": %lld, "
      "\"bytes\": %lld, \"publish_failed\": %lld, \"stored\": %lld, \"start\": %.6f, "
      "\"end\": %.6f, \"last_stored\": %.6f, \"paused_s\": %.3f, \"replay_lost\": %lld, "
      "\"replay_missing_frames\": %lld, \"replay_dropped\": %lld}\n",
      kind.c_str(), actor_id, static_cast<long long>(published), static_cast<long long>(messages),
      static_cast<long long>(bytes), static_cast<long long>(failed),
      static_cast<long long>(replay.stored - stored_at_start), start, end, replay.stored_changed,
      paused, static_cast<long long>(replay.lost - lost_at_start),
      static_cast<long long>(replay.missing_frames - missing_at_start),
      static_cast<long long>(replay.dropped - dropped_at_start));
  return 0;
}

}  // namespace

int main(int argc, char** argv) { return rl::RunMain("bench_transport", Main, argc, argv); }
