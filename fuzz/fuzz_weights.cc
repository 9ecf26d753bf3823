// Fuzz target: weights chunks as an actor receives them. A real rl::actor::Actor on an in-process
// bus (CartPole-v1 with a Q-network, or Pendulum-v1 with a TD3 actor network) gets each chunk
// through the bus's receive path (decode, header checks, Validate()) and its RL_WEIGHTS handler:
// the WeightsAssembler, whose buffers are bounded by the network the actor builds from the
// chunk's architecture (actor/weights_assembler.h), the network built and checked against the
// env, the assembled parameters set; then the actor steps its env with them.
// Input: one byte selecting the env (handler_setup.h: kWeightsEnvs), then records
// (fuzz_support.h: Records), each an encoded weights_chunk_t, fingerprint first, delivered with a
// valid header.
// Contract checked: nothing crashes or leaks, and no chunk makes the actor allocate beyond two
// buffers of a network it accepts (the run's RSS limit).
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "actor/actor.h"
#include "common/channels.h"
#include "fuzz/fuzz_support.h"
#include "fuzz/handler_setup.h"
#include "rlmsg/weights_chunk_t.hpp"

namespace {

rl::actor::ActorConfig Config(uint8_t selector) {
  rl::actor::ActorConfig c;
  c.env_id = rl::fuzz::Select(rl::fuzz::kWeightsEnvs, selector);
  c.batch_size = 4;
  if (c.env_id == "Pendulum-v1") c.exploration.mode = "gaussian";
  return c;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size == 0) return 0;
  rl::Bus bus(rl::InProcessBusConfig(rl::fuzz::kHandlerRunId, "actor-0"));
  rl::actor::Actor actor(Config(data[0]), &bus);
  int64_t seq = 0;
  for (const std::string_view record : rl::fuzz::Records(data + 1, size - 1)) {
    rl::fuzz::Deliver<rlmsg::weights_chunk_t>(&bus, rl::channels::kWeights, record, "learner", &seq,
                                              rl::Port::kBulk);
  }
  if (actor.weights_version() >= 0) {
    // The network acts on the env with the parameters it was given (finite: Validate()).
    for (int i = 0; i < 4; ++i) actor.StepEnvs();
  }
  return 0;
}
