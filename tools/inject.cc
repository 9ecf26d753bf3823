// inject: sends bad messages on every channel of a run and checks that every process counted and
// dropped them (the integration test of robustness).
//
// For each channel it sends `count` messages of each kind: random bytes, truncated real messages,
// well-formed messages of another run, well-formed messages of this run with invalid content, and
// each invalid message a second time (replayed). With the run's key (--key-file) the invalid ones
// carry a right MAC, and three more kinds go out: no MAC, a MAC of another key, a right MAC over
// a message with one bit flipped after signing. Then it waits until the stats of each expected
// role show at least the drops its subscriptions imply, and exits 0; 1 if they do not within
// --timeout seconds.
//
// With --replayed-log FILE it sends nothing: it counts the messages per channel of an lcm-logger
// recording of the run, waits until the replay's inserts stand still (the test has stopped the
// actors), prints "inject: ready for playback", and then waits until the replay and the evaluator
// have dropped as replayed (or as stale, when the recording is older than their freshness window)
// every recorded message of their channels (the test plays the file with lcm-logplayer
// meanwhile), with the replay's inserts and every lost count unchanged.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <map>
#include <memory>
#include <random>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "common/channels.h"
#include "common/clock.h"
#include "common/message_auth.h"
#include "common/message_examples.h"
#include "common/options.h"
#include "common/shutdown.h"
#include "envs/specs.h"

namespace {

struct Drops {
  int64_t malformed = 0, foreign = 0, invalid = 0, unauthenticated = 0, stale = 0, replayed = 0,
          lost = 0;
  int64_t inserts = 0;  // the replay's
  double seen = 0;
};

template <class Stats>
Drops DropsOf(const Stats& s) {
  Drops d;
  d.malformed = s.dropped_malformed;
  d.foreign = s.dropped_foreign;
  d.invalid = s.dropped_invalid;
  d.unauthenticated = s.dropped_unauthenticated;
  d.stale = s.dropped_stale;
  d.replayed = s.dropped_replayed;
  d.lost = s.lost;
  d.seen = rl::MonoSeconds();
  return d;
}

template <class Msg>
std::vector<uint8_t> Encode(Msg m, const rlmsg::header_t& header) {
  m.header = header;
  std::vector<uint8_t> bytes(static_cast<size_t>(m.getEncodedSize()));
  m.encode(bytes.data(), 0, static_cast<int>(bytes.size()));
  return bytes;
}

// One channel: a well-formed message of the channel's type, and one with invalid content (sent
// on the channel's port, common/channels.h).
struct Target {
  std::string channel;
  std::function<std::vector<uint8_t>(const rlmsg::header_t&)> good;
  std::function<std::vector<uint8_t>(const rlmsg::header_t&)> invalid;
};

// The run env's shapes (--env), so that an invalid message differs from a valid one only in
// the field it breaks: a flat observation of the env's size and a valid action (index 0, or the
// middle of every dimension's bounds).
struct Shape {
  int obs_size = 4;
  std::vector<float> action = {0};
};
Shape& RunShape() {
  static Shape shape;
  return shape;
}

// One transition of the run env, flat or in stacks of two 2x2 frames (common/message_examples.h),
// with the env's valid action.
template <class Msg>
Msg WithRunAction(Msg m) {
  m.action = RunShape().action;
  m.action_width = m.num_action_values = static_cast<int32_t>(m.action.size());
  return m;
}
rlmsg::transition_batch_t Transitions() {
  return WithRunAction(rl::examples::FlatTransitions(0, 1, RunShape().obs_size));
}
rlmsg::transition_batch_t PixelTransitions() {
  return WithRunAction(rl::examples::PixelTransitions(0, 1, 2, 2));
}
rlmsg::sample_batch_t Samples() {
  return WithRunAction(rl::examples::FlatSamples(1, RunShape().obs_size));
}
rlmsg::sample_batch_t PixelSamples() {
  return WithRunAction(rl::examples::PixelSamples(1, 2, 2, 2));
}
rlmsg::priority_update_t Priorities() { return rl::examples::Example<rlmsg::priority_update_t>(); }
rlmsg::weights_chunk_t Chunk() { return rl::examples::WeightsChunk("linear(4,2)", 10, 1, 0); }

// A target on `channel` whose well-formed message is make() and whose invalid one is make() with
// break_it() applied.
template <class Make, class Break>
Target Broken(const char* channel, Make make, Break break_it) {
  return {channel, [make](const rlmsg::header_t& r) { return Encode(make(), r); },
          [make, break_it](const rlmsg::header_t& r) {
            auto m = make();
            break_it(m);
            return Encode(m, r);
          }};
}

std::vector<Target> Targets() {
  const float nan = std::nanf("");
  std::vector<Target> t;
  t.push_back(
      Broken(rl::channels::kTransitions, Transitions, [nan](auto& m) { m.reward[0] = nan; }));
  t.push_back({rl::channels::kSampleRequest,
               [](const rlmsg::header_t& r) {
                 rlmsg::sample_request_t m{};
                 m.batch_size = 1;
                 m.request_id = 1'000'000'000;
                 return Encode(m, r);
               },
               [](const rlmsg::header_t& r) {
                 rlmsg::sample_request_t m{};
                 m.batch_size = -5;
                 return Encode(m, r);
               }});
  t.push_back(Broken(rl::channels::kSamples, Samples, [nan](auto& m) { m.obs[0] = nan; }));
  // Frame ids must increase.
  t.push_back(Broken(rl::channels::kTransitions, PixelTransitions, [](auto& m) {
    m.frame_id = {1, 0};
  }));
  // The action fields: a NaN action (refused by every receiver's check), and actions that are
  // well-formed but not the run env's (refused by the replay, which knows the env): a value far
  // out of range (an index for a discrete env, a bound for a continuous one), and one action
  // value too many. Each counts as one invalid message.
  t.push_back(
      Broken(rl::channels::kTransitions, Transitions, [nan](auto& m) { m.action[0] = nan; }));
  t.push_back(Broken(rl::channels::kTransitions, Transitions, [](auto& m) { m.action[0] = 99; }));
  t.push_back(Broken(rl::channels::kTransitions, Transitions, [](auto& m) {
    m.action.push_back(m.action[0]);
    m.action_width = m.num_action_values = static_cast<int32_t>(m.action.size());
  }));
  t.push_back(
      Broken(rl::channels::kPriorities, Priorities, [nan](auto& m) { m.priority[0] = nan; }));
  // A discount outside [0, 1].
  t.push_back(Broken(rl::channels::kSamples, PixelSamples, [](auto& m) { m.discount[0] = 2; }));
  t.push_back(Broken(rl::channels::kWeights, Chunk, [](auto& m) { m.chunk_index = 3; }));
  t.push_back({rl::channels::kFlow,
               [](const rlmsg::header_t& r) {
                 rlmsg::flow_control_t m{};
                 m.insert_allowed = 1;
                 return Encode(m, r);
               },
               [](const rlmsg::header_t& r) {
                 rlmsg::flow_control_t m{};
                 m.insert_allowed = 7;
                 return Encode(m, r);
               }});
  t.push_back({rl::channels::kCheckpoint,
               [](const rlmsg::header_t& r) {
                 rlmsg::checkpoint_t m{};
                 m.path = "/nonexistent/ckpt.bin";
                 return Encode(m, r);
               },
               [](const rlmsg::header_t& r) {
                 rlmsg::checkpoint_t m{};  // empty path
                 return Encode(m, r);
               }});
  // Channels nobody subscribes to in a given role still get the garbage.
  for (const char* ch : {rl::channels::kEval, rl::channels::kStatsActor, rl::channels::kStatsReplay,
                         rl::channels::kStatsLearner, rl::channels::kStatsEvaluator}) {
    t.push_back({ch, [](const rlmsg::header_t& r) { return Encode(Transitions(), r); },
                 [](const rlmsg::header_t& r) { return Encode(Transitions(), r); }});
  }
  return t;
}

// The targets each role receives (what its drop counters must reflect): one entry per Target of
// a channel it subscribes to.
const std::map<std::string, std::vector<std::string>>& RoleChannels() {
  static const std::map<std::string, std::vector<std::string>> m = {
      {"replay",
       {rl::channels::kTransitions, rl::channels::kTransitions, rl::channels::kTransitions,
        rl::channels::kTransitions, rl::channels::kTransitions, rl::channels::kSampleRequest,
        rl::channels::kPriorities}},
      {"learner", {rl::channels::kSamples, rl::channels::kSamples}},
      {"actor", {rl::channels::kWeights, rl::channels::kFlow}},
      {"evaluator", {rl::channels::kCheckpoint}},
  };
  return m;
}

// Per role, the smallest counts of its processes (every actor must have dropped enough), from
// the newest stats of each process.
class RoleDrops {
 public:
  explicit RoleDrops(rl::Bus* bus) {
    bus->Subscribe<rlmsg::stats_actor_t>(rl::channels::kStatsActor, [this](const auto& s) {
      by_sender_[s.header.sender] = DropsOf(s);
    });
    bus->Subscribe<rlmsg::stats_replay_t>(rl::channels::kStatsReplay, [this](const auto& s) {
      Drops d = DropsOf(s);
      d.inserts = s.total_inserts;
      by_sender_[s.header.sender] = d;
    });
    bus->Subscribe<rlmsg::stats_learner_t>(rl::channels::kStatsLearner, [this](const auto& s) {
      by_sender_[s.header.sender] = DropsOf(s);
    });
    bus->Subscribe<rlmsg::stats_evaluator_t>(rl::channels::kStatsEvaluator, [this](const auto& s) {
      by_sender_[s.header.sender] = DropsOf(s);
    });
  }

  std::map<std::string, Drops> ByRole() const {
    std::map<std::string, Drops> drops;
    for (const auto& [sender, d] : by_sender_) {
      const std::string role = sender.rfind("actor-", 0) == 0 ? "actor" : sender;
      auto [it, fresh] = drops.try_emplace(role, d);
      if (!fresh) {
        Drops& m = it->second;
        m.malformed = std::min(m.malformed, d.malformed);
        m.foreign = std::min(m.foreign, d.foreign);
        m.invalid = std::min(m.invalid, d.invalid);
        m.unauthenticated = std::min(m.unauthenticated, d.unauthenticated);
        m.stale = std::min(m.stale, d.stale);
        m.replayed = std::min(m.replayed, d.replayed);
        m.seen = std::min(m.seen, d.seen);
      }
    }
    return drops;
  }

 private:
  std::map<std::string, Drops> by_sender_;
};

std::set<std::string> SplitRoles(const std::string& roles) {
  std::set<std::string> expected;
  std::stringstream ss(roles);
  for (std::string r; std::getline(ss, r, ',');) expected.insert(r);
  return expected;
}

// Recorded messages a process refused since `base`: as replayed, or as stale when the recording
// is older than its freshness window.
int64_t Refused(const Drops& now, const Drops& base) {
  return now.replayed - base.replayed + now.stale - base.stale;
}

// --replayed-log: see the top of the file.
int CheckReplayed(rl::Bus& bus, const std::string& log_path, double timeout) {
  std::map<std::string, int64_t> recorded;  // messages per channel
  {
    lcm::LogFile log(log_path, "r");
    if (!log.good()) throw std::runtime_error("cannot read the recording " + log_path);
    while (const lcm::LogEvent* e = log.readNextEvent()) ++recorded[e->channel];
  }
  auto count = [&recorded](std::initializer_list<const char*> channels) {
    int64_t n = 0;
    for (const char* c : channels) n += recorded.count(c) ? recorded.at(c) : 0;
    return n;
  };
  const int64_t want_replay =
      count({rl::channels::kTransitions, rl::channels::kSampleRequest, rl::channels::kPriorities});
  const int64_t want_evaluator = count({rl::channels::kCheckpoint});
  std::printf("inject: the recording holds %lld messages for the replay, %lld for the evaluator\n",
              static_cast<long long>(want_replay), static_cast<long long>(want_evaluator));
  if (want_replay == 0) throw std::runtime_error("the recording holds no message for the replay");
  RoleDrops drops(&bus);
  // The baseline: the replay's inserts stand still over two reports a second apart.
  const double deadline = rl::MonoSeconds() + timeout;
  Drops base_replay, base_evaluator;
  double last_seen = 0;
  int64_t last_inserts = -1;
  int same = 0;
  while (same < 2) {
    if (rl::MonoSeconds() > deadline || rl::StopRequested()) {
      std::printf("inject: the replay's inserts never stood still\n");
      return 1;
    }
    bus.Handle(100);
    const auto roles = drops.ByRole();
    if (!roles.count("replay") || !roles.count("evaluator")) continue;
    const Drops& r = roles.at("replay");
    if (r.seen - last_seen < 1.0) continue;
    same = r.inserts == last_inserts ? same + 1 : 0;
    last_inserts = r.inserts;
    last_seen = r.seen;
    base_replay = r;
    base_evaluator = roles.at("evaluator");
  }
  std::printf("inject: ready for playback (replay: inserts %lld replayed %lld lost %lld)\n",
              static_cast<long long>(base_replay.inserts),
              static_cast<long long>(base_replay.replayed),
              static_cast<long long>(base_replay.lost));
  std::fflush(stdout);
  Drops r = base_replay, e = base_evaluator;
  while (rl::MonoSeconds() < deadline && !rl::StopRequested()) {
    bus.Handle(100);
    const auto roles = drops.ByRole();
    r = roles.at("replay");
    e = roles.at("evaluator");
    if (Refused(r, base_replay) >= want_replay && Refused(e, base_evaluator) >= want_evaluator) {
      break;
    }
  }
  const bool ok = Refused(r, base_replay) == want_replay &&
                  Refused(e, base_evaluator) == want_evaluator &&
                  r.inserts == base_replay.inserts && r.lost == base_replay.lost &&
                  e.lost == base_evaluator.lost;
  std::printf(
      "inject: replay: replayed or stale %lld/%lld inserts %lld -> %lld lost %lld -> %lld; "
      "evaluator: replayed or stale %lld/%lld lost %lld -> %lld %s\n",
      static_cast<long long>(Refused(r, base_replay)), static_cast<long long>(want_replay),
      static_cast<long long>(base_replay.inserts), static_cast<long long>(r.inserts),
      static_cast<long long>(base_replay.lost), static_cast<long long>(r.lost),
      static_cast<long long>(Refused(e, base_evaluator)), static_cast<long long>(want_evaluator),
      static_cast<long long>(base_evaluator.lost), static_cast<long long>(e.lost),
      ok ? "ok" : "WRONG");
  return ok ? 0 : 1;
}

// Sends `count` messages of each bad kind on every target's channel (the top of this file says
// which), paced (1 ms apart) so that nothing is lost on the way. Messages that pass the MAC check
// take the channel's next sequence number; the others reuse it, so that no receiver counts a gap.
// Returns how many it sent.
int SendBadMessages(rl::Bus& bus, int64_t run_id, int count, uint64_t seed) {
  const bool keyed = !bus.config().key.empty();
  std::unique_ptr<rl::MessageAuthenticator> auth, other;
  if (keyed) {
    auth = std::make_unique<rl::MessageAuthenticator>(bus.config().key);
    other = std::make_unique<rl::MessageAuthenticator>(std::string(rl::kKeyBytes, '\x5a'));
  }
  rlmsg::header_t header{};
  header.run_id = run_id;
  header.sender = "inject";
  header.incarnation = rl::WallMicros();
  const size_t mac_at = rl::MacOffset(header.sender.size());
  std::map<std::string, int64_t> next_seq;
  std::mt19937_64 rng(seed);
  std::uniform_int_distribution<int> byte(0, 255), length(1, 300);
  int sent = 0;
  for (const Target& t : Targets()) {
    auto send = [&](const std::vector<uint8_t>& bytes) {
      bus.PublishRaw(t.channel, bytes.data(), bytes.size());
      ++sent;
    };
    for (int k = 0; k < count; ++k) {
      header.run_id = run_id;
      header.seq = next_seq[t.channel];
      header.utime = rl::WallMicros();
      std::vector<uint8_t> junk(static_cast<size_t>(length(rng)));
      for (auto& b : junk) b = static_cast<uint8_t>(byte(rng));
      send(junk);
      std::vector<uint8_t> good = t.good(header);
      good.resize(good.size() / 2);
      send(good);
      if (keyed) {
        send(t.good(header));  // no MAC
        std::vector<uint8_t> forged = t.good(header);
        other->Sign(t.channel, forged.data(), forged.size(), mac_at);
        send(forged);  // another key's MAC
        // Signed as a later incarnation of ours (that sends nothing else), so that this MAC's
        // nonce is not the one of the invalid message below (common/message_auth.h).
        rlmsg::header_t later = header;
        later.incarnation = header.incarnation + 1;
        std::vector<uint8_t> flipped = t.good(later);
        auth->Sign(t.channel, flipped.data(), flipped.size(), mac_at);
        flipped[mac_at - 9] ^= 0x10;  // in header.utime: still decodes
        send(flipped);                // changed after signing
      }
      header.run_id = run_id ^ 0x5A5A5A5A5A5ALL;
      send(t.good(header));  // another run's
      header.run_id = run_id;
      header.seq = next_seq[t.channel]++;
      std::vector<uint8_t> invalid = t.invalid(header);
      if (keyed) auth->Sign(t.channel, invalid.data(), invalid.size(), mac_at);
      send(invalid);
      send(invalid);  // the same again: replayed
      bus.Handle(1);
    }
  }
  return sent;
}

// Waits up to `timeout` s for every role in `expected` to report the drops of each kind that the
// channels it subscribes to imply, prints a line per role, and returns 0 if all did, 1 if not.
int CheckDrops(rl::Bus& bus, const RoleDrops& drops, const std::set<std::string>& expected,
               int count, bool keyed, double timeout) {
  auto enough = [&](const std::string& role, const Drops& d) {
    const int64_t n = count * static_cast<int64_t>(RoleChannels().at(role).size());
    // A truncated copy whose header is whole fails the MAC check before it is decoded, where
    // there is a key: malformed or unauthenticated.
    return d.malformed >= n && d.malformed + d.unauthenticated >= (keyed ? 5 : 2) * n &&
           d.foreign >= n && d.invalid >= n && d.replayed >= n &&
           d.unauthenticated >= (keyed ? 3 * n : 0);
  };
  const double deadline = rl::MonoSeconds() + timeout;
  const double sent_at = rl::MonoSeconds();
  while (rl::MonoSeconds() < deadline && !rl::StopRequested()) {
    bus.Handle(100);
    const auto by_role = drops.ByRole();
    bool all = true;
    for (const std::string& role : expected) {
      const auto it = by_role.find(role);
      if (it == by_role.end() || it->second.seen < sent_at || !enough(role, it->second)) {
        all = false;
      }
    }
    if (all) break;
  }
  int status = 0;
  const auto by_role = drops.ByRole();
  for (const std::string& role : expected) {
    const int64_t n = count * static_cast<int64_t>(RoleChannels().at(role).size());
    const Drops d = by_role.count(role) ? by_role.at(role) : Drops{};
    const bool ok = enough(role, d);
    std::printf(
        "inject: %-9s malformed %lld/%lld foreign %lld/%lld invalid %lld/%lld replayed %lld/%lld "
        "unauthenticated %lld/%lld %s\n",
        role.c_str(), static_cast<long long>(d.malformed), static_cast<long long>(n),
        static_cast<long long>(d.foreign), static_cast<long long>(n),
        static_cast<long long>(d.invalid), static_cast<long long>(n),
        static_cast<long long>(d.replayed), static_cast<long long>(n),
        static_cast<long long>(d.unauthenticated), static_cast<long long>(keyed ? 3 * n : 0),
        ok ? "ok" : "MISSING");
    if (!ok) status = 1;
  }
  return status;
}

int Main(int argc, char** argv) {
  rl::CommonOptions common;
  int count = 20;
  double timeout = 30;
  std::string roles = "replay,learner,actor,evaluator";
  std::string env = "CartPole-v1";
  std::string replayed_log;
  uint64_t seed = 1;
  rl::po::options_description desc("Options");
  rl::AddCommonOptions(&desc, &common);
  desc.add_options()  //
      ("count", rl::po::value(&count)->default_value(count),
       "messages of each kind per channel")                                                    //
      ("roles", rl::po::value(&roles)->default_value(roles), "roles whose drops are checked")  //
      ("timeout", rl::po::value(&timeout)->default_value(timeout),
       "seconds to wait for the stats to show the drops")  //
      ("env", rl::po::value(&env)->default_value(env),
       "the run's env (flat observations): transitions and samples get its shapes")    //
      ("seed", rl::po::value(&seed)->default_value(seed), "seed of the random bytes")  //
      ("replayed-log", rl::po::value(&replayed_log),
       "send nothing: check that the messages of this recording of the run, played back by "
       "lcm-logplayer, are all dropped as replayed (see the top of tools/inject.cc)");
  rl::po::variables_map vm;
  if (!rl::ParseOptions(argc, argv, "inject",
                        "Usage: inject [options]\n"
                        "Sends malformed, truncated, foreign, invalid, replayed and (with the "
                        "run's key) unauthenticated messages on every channel of a run and checks "
                        "that every process counted and dropped them.",
                        desc, &vm)) {
    return 0;
  }
  rl::InstallStopHandlers();
  rl::Bus bus(common.MakeBusConfig("inject"));
  if (!replayed_log.empty()) return CheckReplayed(bus, replayed_log, timeout);

  const rl::envs::EnvSpec spec = rl::envs::LookupSpec(env);  // throws, naming the known ids
  if (spec.frame_stack > 0) {
    std::fprintf(stderr, "inject: error: --env %s has pixel observations; give a flat env\n",
                 env.c_str());
    return 2;
  }
  RunShape().obs_size = spec.observation_size;
  RunShape().action.assign(static_cast<size_t>(spec.action_width()), 0.0f);
  for (int d = 0; spec.continuous() && d < spec.action_dim; ++d) {
    RunShape().action[static_cast<size_t>(d)] =
        (spec.action_low[static_cast<size_t>(d)] + spec.action_high[static_cast<size_t>(d)]) / 2;
  }
  RoleDrops drops(&bus);
  const bool keyed = !bus.config().key.empty();
  const int sent = SendBadMessages(bus, common.run_id, count, seed);
  std::printf("inject: sent %d bad messages%s\n", sent,
              keyed ? "" : " (no --key-file: none unauthenticated)");
  std::fflush(stdout);
  return CheckDrops(bus, drops, SplitRoles(roles), count, keyed, timeout);
}

}  // namespace

int main(int argc, char** argv) { return rl::RunMain("inject", Main, argc, argv); }
