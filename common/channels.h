// The messages of a run, declared once: each channel with its type (lcmtypes/<type>.lcm), its
// port, who publishes it and who receives it. Everything that lists messages derives from
// RL_MESSAGES: the channel names below, the bus's checks (a channel of this table carries only
// its type, on its port: common/lcm_bus.h), Validate() (common/messages.h), the example messages
// (common/message_examples.h), the fuzz targets and their seeds, tools/inject and the tests.
//
// Adding a message: its .lcm file, a line here, its Validate() in common/messages.cc and its
// example in common/message_examples.cc. Append new lines at the end: the fuzz inputs select a
// type by its index in this table, so the committed corpora keep their meaning.
#pragma once

#include <cstddef>
#include <string_view>

namespace rl {

/// The UDP ports of a run: the main port for small and frequent messages, the bulk port (main + 1)
/// for the weights, so that weights never starve transitions, and the samples port (main + 2) for
/// the replay's sample replies, which only the learner wants: every process on a port copies
/// every datagram of it out of the kernel, and the replies are the run's heaviest traffic (3.6 MB
/// 45 times a second in car_racing_td3), so the actors that listen for weights must not get them.
enum class Port { kMain, kBulk, kSamples };
inline constexpr int kNumPorts = 3;

// X(type, constant, channel name, port), each below its publisher -> receivers: rate.
#define RL_MESSAGES(X)                                                                          \
  /* learner -> evaluator: every M updates */                                                   \
  X(checkpoint_t, kCheckpoint, "RL_CHECKPOINT", kMain)                                          \
  /* evaluator -> monitor, spy: one per scored checkpoint */                                    \
  X(eval_result_t, kEval, "RL_EVAL", kMain)                                                     \
  /* replay -> actors: 20 Hz and on change */                                                   \
  X(flow_control_t, kFlow, "RL_FLOW", kMain)                                                    \
  /* learner -> replay: one per update, with prioritized replay */                              \
  X(priority_update_t, kPriorities, "RL_PRIORITIES", kMain)                                     \
  /* replay -> learner: one per request; flat observations, or the rebuilt stacks as bytes */   \
  X(sample_batch_t, kSamples, "RL_SAMPLES", kSamples)                                           \
  /* learner -> replay: one per update */                                                       \
  X(sample_request_t, kSampleRequest, "RL_SAMPLE_REQUEST", kMain)                               \
  /* actors -> monitor, spy: 4 Hz */                                                            \
  X(stats_actor_t, kStatsActor, "RL_STATS_ACTOR", kMain)                                        \
  /* evaluator -> monitor, spy: 4 Hz */                                                         \
  X(stats_evaluator_t, kStatsEvaluator, "RL_STATS_EVALUATOR", kMain)                            \
  /* learner -> monitor, spy: 4 Hz */                                                           \
  X(stats_learner_t, kStatsLearner, "RL_STATS_LEARNER", kMain)                                  \
  /* replay -> monitor, spy: 4 Hz */                                                            \
  X(stats_replay_t, kStatsReplay, "RL_STATS_REPLAY", kMain)                                     \
  /* actors -> replay: one per batch (16 to 32 transitions); flat observations as floats, or */ \
  /* pixel frames sent once each with transitions naming their stacks by frame id */            \
  X(transition_batch_t, kTransitions, "RL_TRANSITIONS", kMain)                                  \
  /* learner -> actors: every K updates, chunks of at most 48 KB */                             \
  X(weights_chunk_t, kWeights, "RL_WEIGHTS", kBulk)

namespace channels {
#define RL_CHANNEL_NAME(type, constant, name, port) inline constexpr char constant[] = name;
RL_MESSAGES(RL_CHANNEL_NAME)
#undef RL_CHANNEL_NAME
}  // namespace channels

/// One line of RL_MESSAGES.
struct MessageInfo {
  std::string_view type;  // lcm-gen's name without the package: "transition_batch_t"
  std::string_view channel;
  Port port;
};

#define RL_MESSAGE_INFO(type, constant, name, port) MessageInfo{#type, name, Port::port},
inline constexpr MessageInfo kMessages[] = {RL_MESSAGES(RL_MESSAGE_INFO)};
#undef RL_MESSAGE_INFO
inline constexpr size_t kNumMessages = sizeof(kMessages) / sizeof(kMessages[0]);

/// The line of `channel`, or nullptr for a channel of no run message (tests, tools). O(types).
constexpr const MessageInfo* FindChannel(std::string_view channel) {
  for (const MessageInfo& m : kMessages) {
    if (m.channel == channel) return &m;
  }
  return nullptr;
}

/// The index of `type` ("transition_batch_t" or lcm-gen's "rlmsg.transition_batch_t") in
/// kMessages, or -1 for a type of no channel (header_t).
constexpr int MessageIndex(std::string_view type) {
  if (type.substr(0, 6) == "rlmsg.") type.remove_prefix(6);
  for (size_t i = 0; i < kNumMessages; ++i) {
    if (kMessages[i].type == type) return static_cast<int>(i);
  }
  return -1;
}

}  // namespace rl
