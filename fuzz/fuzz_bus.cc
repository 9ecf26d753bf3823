// Fuzz target: the bus's whole receive path, as a daemon runs it on every packet of its port:
// decode (rl::Decode), run id, MAC (common/message_auth.h), sender incarnation and sequence
// freshness, Validate(), handler. Input: as fuzz_messages's (one byte selecting the type, then an
// encoded message), published on that type's channel to a bus with a key and subscribed to every
// type.
//
// Each input goes in three times: as it is (its MAC, if any, is almost surely wrong: dropped as
// unauthenticated or earlier), then signed with the bus's key when its header can be found, twice
// (the first copy passes the MAC and reaches the freshness checks, Validate() and the handler; the
// second is the same message again and must never reach the handler: replayed). A handler call
// for the second copy, or counters that do not add up, abort.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "common/lcm_bus.h"
#include "common/message_auth.h"
#include "fuzz/message_types.h"

namespace {

constexpr int64_t kRunId = 42;

[[noreturn]] void Fail(const char* what) {
  std::fprintf(stderr, "fuzz_bus: %s\n", what);
  std::abort();
}

struct Harness {
  Harness() : bus(Config()), auth(Key()) {
#define RL_FUZZ_SUBSCRIBE(type)                     \
  channels.push_back(std::string("FUZZ_") + #type); \
  bus.Subscribe<rlmsg::type>(channels.back(), [this](const rlmsg::type&) { ++handled; });
    RL_FUZZ_MESSAGE_TYPES(RL_FUZZ_SUBSCRIBE)
#undef RL_FUZZ_SUBSCRIBE
  }
  static std::string Key() { return std::string(rl::kKeyBytes, '\x2a'); }
  static rl::BusConfig Config() {
    rl::BusConfig c = rl::InProcessBusConfig(kRunId, "fuzz");
    c.key = Key();
    return c;
  }

  rl::Bus bus;
  rl::MessageAuthenticator auth;
  std::vector<std::string> channels;
  int64_t handled = 0;
};

// The header's sender length (after the 8-byte fingerprint and the 8-byte run id), or -1.
int64_t SenderLength(const std::vector<uint8_t>& m) {
  if (m.size() < 20) return -1;
  const int64_t len =
      (int64_t{m[16]} << 24) | (int64_t{m[17]} << 16) | (int64_t{m[18]} << 8) | int64_t{m[19]};
  return len >= 1 ? len - 1 : -1;  // lcm strings count their NUL
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static Harness* h = new Harness();  // one bus for the whole run (its LCM instance is costly)
  if (size == 0) return 0;
  const std::string& channel = h->channels[data[0] % h->channels.size()];
  std::vector<uint8_t> msg(data + 1, data + size);
  const rl::BusCounters before = h->bus.counters();
  const int64_t handled_before = h->handled;

  h->bus.PublishRaw(channel, msg.data(), msg.size());
  h->bus.Handle(0);
  const int64_t sender = SenderLength(msg);
  bool signed_twice = false;
  if (sender >= 0) {
    const size_t at = rl::MacOffset(static_cast<size_t>(sender));
    if (at + rl::kMacBytes <= msg.size()) {
      std::memset(msg.data() + at, 0, rl::kMacBytes);
      if (!h->auth.Sign(channel, msg.data(), msg.size(), at)) Fail("cannot sign");
      h->bus.PublishRaw(channel, msg.data(), msg.size());
      h->bus.Handle(0);
      const int64_t after_first = h->handled;
      h->bus.PublishRaw(channel, msg.data(), msg.size());
      h->bus.Handle(0);
      if (h->handled != after_first) Fail("a message reached its handler twice");
      signed_twice = true;
    }
  }
  // Every packet is handled once or dropped once, by one reason.
  const rl::BusCounters& after = h->bus.counters();
  const int64_t packets = signed_twice ? 3 : 1;
  const int64_t accounted = (after.received - before.received) + after.dropped() - before.dropped();
  if (accounted != packets) Fail("a packet was neither handled nor counted as dropped");
  if (after.received - before.received != h->handled - handled_before) {
    Fail("received does not count the handler calls");
  }
  return 0;
}
