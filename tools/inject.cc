// inject: sends bad messages on every channel of a run and checks that every process counted and
// dropped them (the integration test of robustness).
//
// For each channel it sends `count` messages of each kind: random bytes, truncated real messages,
// well-formed messages of another run, and well-formed messages of this run with invalid content.
// Then it waits until the stats of each expected role show at least the drops its subscriptions
// imply, and exits 0; 1 if they do not within --timeout seconds.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <map>
#include <random>
#include <set>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "common/channels.h"
#include "common/clock.h"
#include "common/options.h"
#include "common/shutdown.h"
#include "envs/specs.h"

namespace {

struct Drops {
  int64_t malformed = 0, foreign = 0, invalid = 0;
  double seen = 0;
};

template <class Msg>
std::vector<uint8_t> Encode(Msg m, int64_t run_id) {
  m.header.run_id = run_id;
  m.header.sender = "inject";
  std::vector<uint8_t> bytes(static_cast<size_t>(m.getEncodedSize()));
  m.encode(bytes.data(), 0, static_cast<int>(bytes.size()));
  return bytes;
}

// One channel: a well-formed message of the channel's type, and one with invalid content.
struct Target {
  std::string channel;
  rl::Port port;
  std::function<std::vector<uint8_t>(int64_t run_id)> good;
  std::function<std::vector<uint8_t>(int64_t run_id)> invalid;
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

// The columns transition and sample batches share: one transition of the run env.
template <class Msg>
Msg OneTransition() {
  const Shape& shape = RunShape();
  Msg m{};
  m.count = 1;
  m.obs_size = m.num_values = shape.obs_size;
  m.obs = m.next_obs = std::vector<float>(static_cast<size_t>(shape.obs_size), 0.0f);
  m.action_width = m.num_action_values = static_cast<int32_t>(shape.action.size());
  m.action = shape.action;
  m.reward = {1};
  m.discount = {0.99f};
  return m;
}

// The same with pixel observations instead: stacks of two 2x2 frames.
template <class Msg>
Msg WithPixels(Msg m) {
  m.obs_size = m.num_values = 0;
  m.obs.clear();
  m.next_obs.clear();
  m.height = m.width = m.stack = 2;
  return m;
}

rlmsg::transition_batch_t Transitions() {
  auto m = OneTransition<rlmsg::transition_batch_t>();
  m.episode_id = {0};
  m.priority = {0};
  return m;
}

// Two 2x2 frames and one transition naming them.
rlmsg::transition_batch_t PixelTransitions() {
  auto m = WithPixels(Transitions());
  m.num_frames = 2;
  m.frame_id = {0, 1};
  m.num_bytes = 8;
  m.frames.assign(8, 100);
  m.num_refs = 2;
  m.obs_frames = {0, 0};
  m.next_obs_frames = {0, 1};
  return m;
}

rlmsg::sample_batch_t Samples() {
  auto m = OneTransition<rlmsg::sample_batch_t>();
  m.requester = "learner";
  m.index = {0};
  m.weight = {1};
  return m;
}

rlmsg::sample_batch_t PixelSamples() {
  auto m = WithPixels(Samples());
  m.num_bytes = 8;
  m.obs_pixels.assign(8, 0);
  m.next_obs_pixels.assign(8, 0);
  return m;
}

rlmsg::priority_update_t Priorities() {
  rlmsg::priority_update_t m{};
  m.count = 1;
  m.index = {0};
  m.priority = {1};
  return m;
}

rlmsg::weights_chunk_t Chunk() {
  rlmsg::weights_chunk_t m{};
  m.version = 1;
  m.architecture = "linear(4,2)";
  m.total_size = 2;
  m.chunk_index = 0;
  m.num_chunks = 1;
  m.offset = 0;
  m.count = 2;
  m.data = {0, 0};
  return m;
}

std::vector<Target> Targets() {
  const float nan = std::nanf("");
  std::vector<Target> t;
  t.push_back({rl::channels::kTransitions, rl::Port::kMain,
               [](int64_t r) { return Encode(Transitions(), r); },
               [nan](int64_t r) {
                 auto m = Transitions();
                 m.reward[0] = nan;
                 return Encode(m, r);
               }});
  t.push_back({rl::channels::kSampleRequest, rl::Port::kMain,
               [](int64_t r) {
                 rlmsg::sample_request_t m{};
                 m.batch_size = 1;
                 m.request_id = 1'000'000'000;
                 return Encode(m, r);
               },
               [](int64_t r) {
                 rlmsg::sample_request_t m{};
                 m.batch_size = -5;
                 return Encode(m, r);
               }});
  t.push_back({rl::channels::kSamples, rl::Port::kBulk,
               [](int64_t r) { return Encode(Samples(), r); },
               [nan](int64_t r) {
                 auto m = Samples();
                 m.obs[0] = nan;
                 return Encode(m, r);
               }});
  t.push_back({rl::channels::kTransitions, rl::Port::kMain,
               [](int64_t r) { return Encode(PixelTransitions(), r); },
               [](int64_t r) {
                 auto m = PixelTransitions();
                 m.frame_id = {1, 0};  // ids must increase
                 return Encode(m, r);
               }});
  // The action fields: a NaN action (refused by every receiver's check), and actions that are
  // well-formed but not the run env's (refused by the replay, which knows the env): a value far
  // out of range (an index for a discrete env, a bound for a continuous one), and one action
  // value too many. Each counts as one invalid message.
  t.push_back({rl::channels::kTransitions, rl::Port::kMain,
               [](int64_t r) { return Encode(Transitions(), r); },
               [nan](int64_t r) {
                 auto m = Transitions();
                 m.action[0] = nan;
                 return Encode(m, r);
               }});
  t.push_back({rl::channels::kTransitions, rl::Port::kMain,
               [](int64_t r) { return Encode(Transitions(), r); },
               [](int64_t r) {
                 auto m = Transitions();
                 m.action[0] = 99;
                 return Encode(m, r);
               }});
  t.push_back({rl::channels::kTransitions, rl::Port::kMain,
               [](int64_t r) { return Encode(Transitions(), r); },
               [](int64_t r) {
                 auto m = Transitions();
                 m.action.push_back(m.action[0]);
                 m.action_width = m.num_action_values = static_cast<int32_t>(m.action.size());
                 return Encode(m, r);
               }});
  t.push_back({rl::channels::kPriorities, rl::Port::kMain,
               [](int64_t r) { return Encode(Priorities(), r); },
               [nan](int64_t r) {
                 auto m = Priorities();
                 m.priority[0] = nan;
                 return Encode(m, r);
               }});
  t.push_back({rl::channels::kSamples, rl::Port::kBulk,
               [](int64_t r) { return Encode(PixelSamples(), r); },
               [](int64_t r) {
                 auto m = PixelSamples();
                 m.discount[0] = 2;  // outside [0, 1]
                 return Encode(m, r);
               }});
  t.push_back({rl::channels::kWeights, rl::Port::kBulk,
               [](int64_t r) { return Encode(Chunk(), r); },
               [](int64_t r) {
                 auto m = Chunk();
                 m.chunk_index = 3;
                 return Encode(m, r);
               }});
  t.push_back({rl::channels::kFlow, rl::Port::kMain,
               [](int64_t r) {
                 rlmsg::flow_control_t m{};
                 m.insert_allowed = 1;
                 return Encode(m, r);
               },
               [](int64_t r) {
                 rlmsg::flow_control_t m{};
                 m.insert_allowed = 7;
                 return Encode(m, r);
               }});
  t.push_back({rl::channels::kCheckpoint, rl::Port::kMain,
               [](int64_t r) {
                 rlmsg::checkpoint_t m{};
                 m.path = "/nonexistent/ckpt.bin";
                 return Encode(m, r);
               },
               [](int64_t r) {
                 rlmsg::checkpoint_t m{};  // empty path
                 return Encode(m, r);
               }});
  // Channels nobody subscribes to in a given role still get the garbage.
  for (const char* ch : {rl::channels::kEval, rl::channels::kStatsActor, rl::channels::kStatsReplay,
                         rl::channels::kStatsLearner, rl::channels::kStatsEvaluator}) {
    t.push_back({ch, rl::Port::kMain, [](int64_t r) { return Encode(Transitions(), r); },
                 [](int64_t r) { return Encode(Transitions(), r); }});
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

int Main(int argc, char** argv) {
  rl::CommonOptions common;
  int count = 20;
  double timeout = 30;
  std::string roles = "replay,learner,actor,evaluator";
  std::string env = "CartPole-v1";
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
       "the run's env (flat observations): transitions and samples get its shapes")  //
      ("seed", rl::po::value(&seed)->default_value(seed), "seed of the random bytes");
  rl::po::variables_map vm;
  if (!rl::ParseOptions(argc, argv, "inject",
                        "Usage: inject [options]\n"
                        "Sends malformed, truncated, foreign and invalid messages on every channel "
                        "of a run and checks that every process counted and dropped them.",
                        desc, &vm)) {
    return 0;
  }
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
  rl::InstallStopHandlers();
  rl::Bus bus(common.MakeBusConfig("inject"));
  std::map<std::string, Drops> by_sender;  // the newest counts of each process
  auto track = [&by_sender](const std::string& sender, int64_t m, int64_t f, int64_t i) {
    by_sender[sender] = Drops{m, f, i, rl::MonoSeconds()};
  };
  // Per role, the smallest counts of its processes: every actor must have dropped enough.
  auto role_drops = [&by_sender]() {
    std::map<std::string, Drops> drops;
    for (const auto& [sender, d] : by_sender) {
      const std::string role = sender.rfind("actor-", 0) == 0 ? "actor" : sender;
      auto [it, fresh] = drops.try_emplace(role, d);
      if (!fresh) {
        it->second.malformed = std::min(it->second.malformed, d.malformed);
        it->second.foreign = std::min(it->second.foreign, d.foreign);
        it->second.invalid = std::min(it->second.invalid, d.invalid);
        it->second.seen = std::min(it->second.seen, d.seen);
      }
    }
    return drops;
  };
  bus.Subscribe<rlmsg::stats_actor_t>(rl::channels::kStatsActor, [&](const auto& s) {
    track(s.header.sender, s.dropped_malformed, s.dropped_foreign, s.dropped_invalid);
  });
  bus.Subscribe<rlmsg::stats_replay_t>(rl::channels::kStatsReplay, [&](const auto& s) {
    track(s.header.sender, s.dropped_malformed, s.dropped_foreign, s.dropped_invalid);
  });
  bus.Subscribe<rlmsg::stats_learner_t>(rl::channels::kStatsLearner, [&](const auto& s) {
    track(s.header.sender, s.dropped_malformed, s.dropped_foreign, s.dropped_invalid);
  });
  bus.Subscribe<rlmsg::stats_evaluator_t>(rl::channels::kStatsEvaluator, [&](const auto& s) {
    track(s.header.sender, s.dropped_malformed, s.dropped_foreign, s.dropped_invalid);
  });

  // Send, paced (1 ms apart), so that nothing is lost on the way.
  std::mt19937_64 rng(seed);
  std::uniform_int_distribution<int> byte(0, 255), length(1, 300);
  const int64_t foreign_run = common.run_id ^ 0x5A5A5A5A5A5ALL;
  int sent = 0;
  for (const Target& t : Targets()) {
    for (int k = 0; k < count; ++k) {
      std::vector<uint8_t> junk(static_cast<size_t>(length(rng)));
      for (auto& b : junk) b = static_cast<uint8_t>(byte(rng));
      bus.PublishRaw(t.channel, junk.data(), junk.size(), t.port);
      std::vector<uint8_t> good = t.good(common.run_id);
      good.resize(good.size() / 2);
      bus.PublishRaw(t.channel, good.data(), good.size(), t.port);
      std::vector<uint8_t> foreign = t.good(foreign_run);
      bus.PublishRaw(t.channel, foreign.data(), foreign.size(), t.port);
      std::vector<uint8_t> invalid = t.invalid(common.run_id);
      bus.PublishRaw(t.channel, invalid.data(), invalid.size(), t.port);
      sent += 4;
      bus.Handle(1);
    }
  }
  std::printf("inject: sent %d bad messages\n", sent);
  std::fflush(stdout);

  // Wait for every role's counters to reach what its subscriptions imply.
  std::set<std::string> expected;
  std::stringstream ss(roles);
  for (std::string r; std::getline(ss, r, ',');) expected.insert(r);
  const double deadline = rl::MonoSeconds() + timeout;
  const double sent_at = rl::MonoSeconds();
  while (rl::MonoSeconds() < deadline && !rl::StopRequested()) {
    bus.Handle(100);
    const auto drops = role_drops();
    bool all = true;
    for (const std::string& role : expected) {
      const auto it = drops.find(role);
      const int64_t n = count * static_cast<int64_t>(RoleChannels().at(role).size());
      if (it == drops.end() || it->second.seen < sent_at || it->second.malformed < 2 * n ||
          it->second.foreign < n || it->second.invalid < n) {
        all = false;
      }
    }
    if (all) break;
  }
  int status = 0;
  const auto drops = role_drops();
  for (const std::string& role : expected) {
    const int64_t n = count * static_cast<int64_t>(RoleChannels().at(role).size());
    const Drops d = drops.count(role) ? drops.at(role) : Drops{};
    const bool ok = d.malformed >= 2 * n && d.foreign >= n && d.invalid >= n;
    std::printf("inject: %-9s malformed %lld/%lld foreign %lld/%lld invalid %lld/%lld %s\n",
                role.c_str(), static_cast<long long>(d.malformed), static_cast<long long>(2 * n),
                static_cast<long long>(d.foreign), static_cast<long long>(n),
                static_cast<long long>(d.invalid), static_cast<long long>(n),
                ok ? "ok" : "MISSING");
    if (!ok) status = 1;
  }
  return status;
}

}  // namespace

int main(int argc, char** argv) { return rl::RunMain("inject", Main, argc, argv); }
