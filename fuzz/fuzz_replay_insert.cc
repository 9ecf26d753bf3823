// Fuzz target: transition batches as the replay stores them. A real ReplayService (replay_setup.h:
// flat uniform, flat prioritized or pixel tables, each filled with two batches of two actors
// first) gets each batch through the bus's receive path (decode, header checks, Validate()) and
// its RL_TRANSITIONS handler: the actor id bound (max_actors), the action check, the flat table or
// the pixel table (frames stored once, each actor's window of frame ids, stacks named by id), the
// sampler and the rate limiter. Then the service inserts one batch more and serves two sample
// requests with priority updates, so that a batch that left the tables inconsistent shows up.
// Input: one byte selecting the configuration, then records (fuzz_support.h: Records), each an
// encoded transition_batch_t, fingerprint first, delivered with a valid header.
// Contract checked: nothing crashes or leaks, and the tables serve afterwards.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "fuzz/fuzz_support.h"
#include "fuzz/replay_setup.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size == 0) return 0;
  rl::fuzz::Replica replica(data[0] % rl::fuzz::kNumReplayConfigs);
  replica.Fill(2, 0);
  for (const std::string_view record : rl::fuzz::Records(data + 1, size - 1)) {
    replica.DeliverTransitions(record);
  }
  replica.Fill(1, 2);
  return 0;
}
