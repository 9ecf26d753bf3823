// Fuzz target: sample replies as the learner trains on them. Each reply goes through the bus's
// receive path (decode, header checks, Validate()) into what Learner::TrainOn does with it
// (learner/learner.cc): BatchDecoder::Decode() for the run's env (flat floats, or pixel stacks
// divided by 255 and randomly shifted), then one update of the run's algorithm (DQN or TD3, small
// networks) on the decoded batch, which refuses a batch that does not fit its networks with
// std::invalid_argument, as the learner counts it.
// Input: one byte selecting the env and algorithm (handler_setup.h: kDecoderSetups), then records
// (fuzz_support.h: Records), each an encoded sample_batch_t, fingerprint first, delivered with a
// valid header.
// Contract checked: a reply is decoded and trained on, or refused by the decoder's reason or by
// std::invalid_argument; nothing else escapes, nothing crashes. (Finite values can still make a
// loss overflow: what a reply holds is data, which a key holder may make up.)
#include <cstddef>
#include <cstdint>
#include <memory>
#include <stdexcept>
#include <string>
#include <string_view>

#include "common/channels.h"
#include "envs/specs.h"
#include "fuzz/fuzz_support.h"
#include "fuzz/handler_setup.h"
#include "learner/batch_decoder.h"
#include "learner/dqn.h"
#include "learner/td3.h"
#include "rlmsg/sample_batch_t.hpp"

namespace {

std::unique_ptr<rl::learner::Algorithm> MakeAlgorithm(const rl::fuzz::DecoderSetup& setup,
                                                      const rl::envs::EnvSpec& spec) {
  if (std::string(setup.algorithm) == "td3") {
    rl::learner::Td3Config c;
    c.hidden = {8, 8};
    return std::make_unique<rl::learner::Td3>(spec, c);
  }
  rl::learner::DqnConfig c;
  c.hidden = {8};
  return std::make_unique<rl::learner::Dqn>(spec.observation_size, spec.num_actions, c);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size == 0) return 0;
  const rl::fuzz::DecoderSetup& setup = rl::fuzz::Select(rl::fuzz::kDecoderSetups, data[0]);
  const rl::envs::EnvSpec spec = rl::envs::LookupSpec(setup.env);
  const std::unique_ptr<rl::learner::Algorithm> algorithm = MakeAlgorithm(setup, spec);
  rl::learner::BatchDecoder decoder(spec, setup.augment_shift, 7);
  rl::Bus bus(rl::InProcessBusConfig(rl::fuzz::kHandlerRunId, "learner"));
  bus.Subscribe<rlmsg::sample_batch_t>(
      rl::channels::kSamples,
      [&](const rlmsg::sample_batch_t& m) {
        rl::learner::Batch batch;
        if (decoder.Decode(m, &batch) != nullptr) return;
        try {
          algorithm->Update(batch);
        } catch (const std::invalid_argument&) {
        }
      },
      rl::Port::kSamples);
  int64_t seq = 0;
  for (const std::string_view record : rl::fuzz::Records(data + 1, size - 1)) {
    rl::fuzz::Deliver<rlmsg::sample_batch_t>(&bus, rl::channels::kSamples, record, "replay", &seq,
                                             rl::Port::kSamples);
  }
  return 0;
}
