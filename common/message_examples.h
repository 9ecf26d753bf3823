// Valid messages built by hand, for the code that sends messages no process made: the unit tests,
// the fuzz seeds (fuzz/fuzz_seeds.cc), tools/inject (which breaks one field of each) and the
// benchmarks. Every function returns a message that passes Validate() (common/messages.h), with
// a header from Header() (sequence number 0 but in the examples); the values follow simple rules
// (documented per function) so that a test can tell which transition or frame it got back.
#pragma once

#include <cstdint>
#include <string>

#include "common/channels.h"
#include "rlmsg/all_types.hpp"

namespace rl::examples {

/// A header from `sender` (sequence number `seq`) of run 0x5eed1234abcd at a fixed time
/// (2025-11-25), incarnation 0, no MAC.
rlmsg::header_t Header(const std::string& sender, int64_t seq);

/// Flat transitions first .. first + count - 1 of `actor` (Header("actor-<actor>", 0)):
/// transition v has obs {v, v + 0.5, v + 1, ...} (obs_size floats), next_obs obs + 1000,
/// action_width values v % 2, reward v, discount 0.99, episode v / 10, priority (v % 7) / 2.
rlmsg::transition_batch_t FlatTransitions(int first, int count, int obs_size, int action_width = 1,
                                          int32_t actor = 0);

/// Pixel transitions of `actor`: frames first .. first + count (ids as numbered, height x width
/// bytes, every byte of frame f equal to (f + actor) mod 256) and transitions t = first .. first +
/// count - 1 in stacks of two naming frames {max(t - 1, first), t} and next stacks {t, t + 1},
/// action t % 3, reward t, discount 0.99, episode 0, priority 0.
rlmsg::transition_batch_t PixelTransitions(int first, int count, int height, int width,
                                           int32_t actor = 0);

/// A reply to "learner" of `count` flat transitions: value e of the obs array 0.1 (e % 9) - 0.4,
/// of next_obs 0.1 (e % 7) - 0.3; transition i has action_width values i % 2, reward i % 3 - 1,
/// discount 0 when i % 4 == 3 (else 0.99), index 100 + i, weight 1 - 0.1 (i % 3).
rlmsg::sample_batch_t FlatSamples(int count, int obs_size, int action_width = 1);

/// The same reply with pixel stacks instead (byte e of obs_pixels 7 e mod 256, of
/// next_obs_pixels 11 e mod 256).
rlmsg::sample_batch_t PixelSamples(int count, int height, int width, int stack,
                                   int action_width = 1);

/// Chunk `chunk_index` of `num_chunks` equal chunks (the last shorter) of version 3 of
/// `total_size` floats of `architecture`: float i of the chunk 0.01 (i - 9), CRC-32 0xCBF43926.
rlmsg::weights_chunk_t WeightsChunk(const std::string& architecture, int32_t total_size,
                                    int32_t num_chunks, int32_t chunk_index);

/// One valid message of each type of common/channels.h, from its usual sender, with every array
/// non-empty where the type allows it.
#define RL_DECLARE_EXAMPLE(type, constant, name, port) void MakeExample(rlmsg::type* m);
RL_MESSAGES(RL_DECLARE_EXAMPLE)
#undef RL_DECLARE_EXAMPLE

template <class Msg>
Msg Example() {
  Msg m{};
  MakeExample(&m);
  return m;
}

}  // namespace rl::examples
