// Checks of received messages, before and after decoding.
//
// Prescan() walks the encoded bytes of a message and checks that every string and array length
// fits in the buffer, before lcm-gen's decoder sizes a vector from a length it has not checked
// (a forged length would otherwise make a daemon allocate gigabytes). It follows the type's .lcm
// file itself (common/lcm_schema.h), so it cannot fall out of step with the types. Validate()
// checks the decoded content: sizes consistent, numbers finite, indices in range. Both return
// nullptr for a good message, or a short reason for the drop counters and logs.
#pragma once

#include <cstddef>
#include <cstdint>
#include <exception>

#include "common/channels.h"
#include "common/lcm_schema.h"
#include "rlmsg/all_types.hpp"

namespace rl {

// Widest action a message may carry (floats per transition).
inline constexpr int32_t kMaxActionWidth = 64;

/// PrescanEncoded() with the schema of Msg's .lcm file. No allocation.
template <class Msg>
const char* Prescan(const Msg*, const uint8_t* data, size_t size) {
  return PrescanEncoded(Msg::getTypeName(), data, size);
}

/// Prescan(), then lcm-gen's decoder, which must use every byte: nullptr, or why the bytes are
/// not a message of type Msg. What the bus does with every message it receives (and what the
/// fuzz targets exercise). Allocates what the message's arrays hold.
template <class Msg>
const char* Decode(const uint8_t* data, size_t size, Msg* msg) {
  if (const char* why = Prescan(msg, data, size)) return why;
  int used = -1;
  try {
    used = msg->decode(data, 0, static_cast<int>(size));
  } catch (const std::exception&) {
    used = -1;
  }
  if (used < 0 || static_cast<size_t>(used) != size) return "does not decode as the channel's type";
  return nullptr;
}

/// Messages a process dropped, all reasons together, from its stats message (stats_*_t).
template <class Stats>
int64_t Dropped(const Stats& s) {
  return s.dropped_malformed + s.dropped_foreign + s.dropped_invalid + s.dropped_unauthenticated +
         s.dropped_stale + s.dropped_replayed;
}

/// One Validate() per message of common/channels.h, defined in messages.cc.
#define RL_DECLARE_VALIDATE(type, constant, name, port) const char* Validate(const rlmsg::type& m);
RL_MESSAGES(RL_DECLARE_VALIDATE)
#undef RL_DECLARE_VALIDATE

}  // namespace rl
