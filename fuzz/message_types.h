// The message types of lcmtypes/*.lcm in the order fuzz_messages reads them: the first input byte
// modulo the count selects the type, the rest is the encoded message. The seed writer
// (fuzz_seeds.cc) prefixes its messages with the same index. Append new types at the end, so that
// the committed corpus keeps its meaning.
#pragma once

#define RL_FUZZ_MESSAGE_TYPES(X) \
  X(checkpoint_t)                \
  X(eval_result_t)               \
  X(flow_control_t)              \
  X(priority_update_t)           \
  X(sample_batch_t)              \
  X(sample_request_t)            \
  X(stats_actor_t)               \
  X(stats_evaluator_t)           \
  X(stats_learner_t)             \
  X(stats_replay_t)              \
  X(transition_batch_t)          \
  X(weights_chunk_t)
