// What the handler targets (fuzz_weights, fuzz_batch_decoder, fuzz_replay_insert,
// fuzz_announced_checkpoint) set up, and what the seed writer (fuzz_seeds.cc) writes inputs for:
// the first byte of an input selects one of these (modulo their count). Append new entries at
// the end, so that the committed corpora keep their meaning.
#pragma once

#include <cstddef>
#include <cstdint>

namespace rl::fuzz {

/// The run id of the handler targets' in-process buses.
inline constexpr int64_t kHandlerRunId = 42;

/// fuzz_weights: the env of the actor that receives the weights (a Q-network for CartPole-v1,
/// a TD3 actor network for Pendulum-v1).
inline constexpr const char* kWeightsEnvs[] = {"CartPole-v1", "Pendulum-v1"};

/// fuzz_batch_decoder: the env and algorithm of the learner that decodes and trains on the
/// sample replies (augment shift 2 for the pixel env, as DrQ shifts).
struct DecoderSetup {
  const char* env;
  const char* algorithm;
  int augment_shift;
};
inline constexpr DecoderSetup kDecoderSetups[] = {
    {"CartPole-v1", "dqn", 0},
    {"Pendulum-v1", "td3", 0},
    {"Catch-v0+pixels(width=5,height=10,stack=2)", "dqn", 2},
};

template <class T, size_t N>
const T& Select(const T (&options)[N], uint8_t selector) {
  return options[selector % N];
}

}  // namespace rl::fuzz
