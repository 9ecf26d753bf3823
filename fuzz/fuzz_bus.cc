// Fuzz target: the bus's whole receive path, as a daemon runs it on every packet of its port:
// the header read from the raw bytes (ReadWireHeader), type, run id, MAC (common/message_auth.h),
// freshness (the time window, the sender incarnation and sequence), then decode (rl::Decode),
// Validate(), handler. Input: as fuzz_messages's (one byte selecting the type, then an encoded
// message), delivered on that type's channel (common/channels.h) to a bus with a key and
// subscribed to every channel.
//
// Each input goes in three times, at a receive time of its own (a window later than the previous
// input's, so that no position of an earlier input guards against this one): as it is (its MAC,
// if any, is almost surely wrong: dropped as unauthenticated or earlier), then, when its header
// can be read, with its time and incarnation moved near the receive time (the input's values
// choose where: inside the window or out of it, an incarnation before its time or after) and
// signed with the bus's key, twice (the first copy passes the MAC and reaches the freshness
// checks, decoding, Validate() and the handler; the second is the same message again and must
// never reach the handler: replayed). A handler call for the second copy, or counters that do
// not add up, abort.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "common/lcm_bus.h"
#include "common/message_auth.h"

namespace {

constexpr int64_t kRunId = 42;
constexpr int64_t kSecond = 1'000'000;
constexpr int64_t kMaxAge = 60 * kSecond;
constexpr int64_t kSkew = 10 * kSecond;
// The first input's receive time (2025), and the step between two inputs' (past the window).
constexpr int64_t kFirstReceive = 1'750'000'000'000'000;
constexpr int64_t kStep = kMaxAge + kSkew + kSecond;

[[noreturn]] void Fail(const char* what) {
  std::fprintf(stderr, "fuzz_bus: %s\n", what);
  std::abort();
}

struct Harness {
  Harness() : bus(Config()), auth(Key()) {
#define RL_FUZZ_SUBSCRIBE(type, constant, name, port) \
  bus.Subscribe<rlmsg::type>(name, [this](const rlmsg::type&) { ++handled; });
    RL_MESSAGES(RL_FUZZ_SUBSCRIBE)
#undef RL_FUZZ_SUBSCRIBE
  }
  static std::string Key() { return std::string(rl::kKeyBytes, '\x2a'); }
  static rl::BusConfig Config() {
    rl::BusConfig c = rl::InProcessBusConfig(kRunId, "fuzz");
    c.key = Key();
    c.max_message_age = kMaxAge;
    c.max_clock_skew = kSkew;
    return c;
  }

  rl::Bus bus;
  rl::MessageAuthenticator auth;
  int64_t handled = 0;
  int64_t inputs = 0;
};

void WriteBigEndian(uint8_t* p, int64_t v) {
  for (int i = 0; i < 8; ++i) p[i] = static_cast<uint8_t>(static_cast<uint64_t>(v) >> (56 - 8 * i));
}

// The input's time and incarnation, moved near `receive`: the time anywhere from 2 s before the
// window to 2 s after it, the incarnation from 2 s before the time to 2 s past the time plus the
// skew (a negative one stays as it is).
void MoveNear(int64_t receive, const rl::WireHeader& h, uint8_t* data) {
  const auto pick = [](int64_t v, int64_t span) {
    return static_cast<int64_t>(static_cast<uint64_t>(v) % static_cast<uint64_t>(span));
  };
  const int64_t utime =
      receive - kMaxAge - 2 * kSecond + pick(h.utime, kMaxAge + kSkew + 4 * kSecond);
  const int64_t incarnation =
      utime + kSkew + 2 * kSecond - pick(h.incarnation, kSkew + 4 * kSecond);
  WriteBigEndian(data + h.mac_offset - 16, utime);
  WriteBigEndian(data + h.mac_offset - 8, h.incarnation < 0 ? h.incarnation : incarnation);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static Harness* h = new Harness();  // one bus for the whole run (its LCM instance is costly)
  if (size == 0) return 0;
  const std::string channel(rl::kMessages[data[0] % rl::kNumMessages].channel);
  std::vector<uint8_t> msg(data + 1, data + size);
  const rl::BusCounters before = h->bus.counters();
  const int64_t handled_before = h->handled;
  const int64_t receive = kFirstReceive + kStep * h->inputs++;

  h->bus.Deliver(channel, msg.data(), msg.size(), receive);
  rl::WireHeader header;
  bool signed_twice = false;
  if (rl::ReadWireHeader(msg.data(), msg.size(), &header) == nullptr) {
    MoveNear(receive, header, msg.data());
    std::memset(msg.data() + header.mac_offset, 0, rl::kMacBytes);
    if (!h->auth.Sign(channel, msg.data(), msg.size(), header.mac_offset)) Fail("cannot sign");
    h->bus.Deliver(channel, msg.data(), msg.size(), receive);
    const int64_t after_first = h->handled;
    h->bus.Deliver(channel, msg.data(), msg.size(), receive);
    if (h->handled != after_first) Fail("a message reached its handler twice");
    signed_twice = true;
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
