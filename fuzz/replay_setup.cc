#include "fuzz/replay_setup.h"

#include <map>
#include <string>
#include <vector>

#include "common/channels.h"
#include "common/message_examples.h"
#include "fuzz/fuzz_support.h"
#include "rlmsg/priority_update_t.hpp"
#include "rlmsg/sample_batch_t.hpp"
#include "rlmsg/sample_request_t.hpp"
#include "rlmsg/transition_batch_t.hpp"

namespace rl::fuzz {
namespace {

constexpr int64_t kRunId = 42;

replay::ReplayServiceOptions Options(int config) {
  replay::ReplayServiceOptions o;
  o.table.capacity = 48;
  o.frame_capacity = 64;
  o.limiter.samples_per_insert = 4;
  o.limiter.min_size_to_sample = 8;
  o.limiter.error_buffer = 400;
  o.prioritized = config != 0;
  o.beta_anneal_samples = 1000;
  o.seed = 7;
  return o;
}

}  // namespace

rlmsg::transition_batch_t SetupBatch(int config, int first, int count, int32_t actor) {
  return config == 2 ? examples::PixelTransitions(first, count, 2, 2, actor)
                     : examples::FlatTransitions(first, count, 2, 1, actor);
}

Replica::Replica(int config) : config_(config), bus_(InProcessBusConfig(kRunId, "replay")) {
  bus_.Subscribe<rlmsg::sample_batch_t>(
      channels::kSamples, [this](const rlmsg::sample_batch_t& m) { replies_.push_back(m); },
      Port::kSamples);
  service_ = std::make_unique<replay::ReplayService>(&bus_, Options(config));
}

template <class Msg>
void Replica::Publish(const std::string& channel, Msg m, const std::string& sender) {
  m.header.run_id = kRunId;
  m.header.sender = sender;
  m.header.seq = seq_[sender]++;
  m.header.utime = WallMicros();
  std::vector<uint8_t> bytes(static_cast<size_t>(m.getEncodedSize()));
  m.encode(bytes.data(), 0, static_cast<int>(bytes.size()));
  bus_.PublishRaw(channel, bytes.data(), bytes.size());
  bus_.Handle(0);
}

void Replica::DeliverTransitions(std::string_view bytes) {
  Deliver<rlmsg::transition_batch_t>(&bus_, channels::kTransitions, bytes, "actor-fuzz",
                                     &fuzz_seq_);
}

void Replica::Fill(int batches, int samples) {
  int next = 0;
  for (int k = 0; k < batches; ++k) {
    const int actor = k % 3;
    const rlmsg::transition_batch_t m = SetupBatch(config_, next, 5, actor);
    Publish(channels::kTransitions, m, "actor-" + std::to_string(actor));
    next += 6;
  }
  for (int k = 0; k < samples; ++k) {
    rlmsg::sample_request_t r{};
    r.request_id = k;
    r.batch_size = 4;
    Publish(channels::kSampleRequest, r, "learner-0");
    service_->Serve();
    bus_.Handle(0);
    if (replies_.empty()) continue;
    const rlmsg::sample_batch_t reply = replies_.back();
    replies_.clear();
    rlmsg::priority_update_t u{};
    u.count = reply.count;
    u.index = reply.index;
    for (int64_t i : reply.index) u.priority.push_back(static_cast<float>(i % 5) + 0.25f);
    Publish(channels::kPriorities, u, "learner-0");
  }
}

}  // namespace rl::fuzz
