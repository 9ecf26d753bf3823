// Checks of received messages, before and after decoding.
//
// Prescan() walks the encoded bytes of a message and checks that every string and array length
// fits in the buffer, before lcm-gen's decoder sizes a vector from a length it has not checked
// (a forged length would otherwise make a daemon allocate gigabytes). Validate() checks the
// decoded content: sizes consistent, numbers finite, indices in range. Both return nullptr for a
// good message, or a short reason for the drop counters and logs.
#pragma once

#include <cstddef>
#include <cstdint>

#include "rlmsg/checkpoint_t.hpp"
#include "rlmsg/eval_result_t.hpp"
#include "rlmsg/flow_control_t.hpp"
#include "rlmsg/priority_update_t.hpp"
#include "rlmsg/sample_batch_t.hpp"
#include "rlmsg/sample_request_t.hpp"
#include "rlmsg/stats_actor_t.hpp"
#include "rlmsg/stats_evaluator_t.hpp"
#include "rlmsg/stats_learner_t.hpp"
#include "rlmsg/stats_replay_t.hpp"
#include "rlmsg/transition_batch_t.hpp"
#include "rlmsg/weights_chunk_t.hpp"

namespace rl {

// Largest array a message may carry (elements), far above any real message.
inline constexpr int64_t kMaxArrayElements = 64 * 1024 * 1024;
// Widest action a message may carry (floats per transition).
inline constexpr int32_t kMaxActionWidth = 64;

const char* Prescan(const rlmsg::transition_batch_t*, const uint8_t* data, size_t size);
const char* Prescan(const rlmsg::sample_batch_t*, const uint8_t* data, size_t size);
const char* Prescan(const rlmsg::weights_chunk_t*, const uint8_t* data, size_t size);
const char* Prescan(const rlmsg::priority_update_t*, const uint8_t* data, size_t size);
// Messages whose only variable part is strings: lcm-gen's decoder checks string lengths, but a
// zero or negative length makes it throw; the bus catches that, so no prescan is needed.
template <class Msg>
const char* Prescan(const Msg*, const uint8_t*, size_t) {
  return nullptr;
}

const char* Validate(const rlmsg::transition_batch_t& m);
const char* Validate(const rlmsg::sample_request_t& m);
const char* Validate(const rlmsg::sample_batch_t& m);
const char* Validate(const rlmsg::weights_chunk_t& m);
const char* Validate(const rlmsg::priority_update_t& m);
const char* Validate(const rlmsg::checkpoint_t& m);
const char* Validate(const rlmsg::flow_control_t& m);
const char* Validate(const rlmsg::eval_result_t& m);
const char* Validate(const rlmsg::stats_actor_t& m);
const char* Validate(const rlmsg::stats_replay_t& m);
const char* Validate(const rlmsg::stats_learner_t& m);
const char* Validate(const rlmsg::stats_evaluator_t& m);

}  // namespace rl
