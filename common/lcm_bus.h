// Bus: the one way our processes talk LCM.
//
// It owns two LCM instances, one for the main port (small, high-rate messages) and one for the
// bulk port (weights, sample replies), so that bulk traffic never starves the rest. Publish()
// fills the header (run id, sender, incarnation, per-channel sequence number, time) and, when the
// run has a key, the MAC (common/message_auth.h). Subscribe() installs a typed handler behind a
// checking decoder, and a message reaches the handler only when it passes every check, in this
// order, each drop counted by its reason:
//   malformed        does not decode as the channel's type (foreign type, torn or forged lengths)
//   foreign          another run's id
//   unauthenticated  no MAC or a wrong one (with a key; a bus without one checks none)
//   replayed         an incarnation of its sender older than one already heard, or a sequence
//                    number of the sender's incarnation on this channel already passed
//   invalid          fails Validate() (or the handler threw)
// Gaps in a sender incarnation's sequence are counted as lost; a newer incarnation (a restarted
// sender) starts a new sequence. Handlers must not throw; if one does, the exception is caught,
// logged and counted as invalid.
//
// Not thread-safe: one thread constructs, publishes and calls Handle().
#pragma once

#include <lcm/lcm-cpp.hpp>

#include <algorithm>
#include <cstdint>
#include <functional>
#include <iterator>
#include <map>
#include <memory>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "common/clock.h"
#include "common/message_auth.h"
#include "common/messages.h"

namespace rl {

// Default URLs: one multicast port per traffic class, 8 MiB receive buffers (see README).
inline constexpr char kDefaultLcmUrl[] = "udpm://239.255.76.67:7667?ttl=0&recv_buf_size=4194304";
inline constexpr char kDefaultLcmBulkUrl[] =
    "udpm://239.255.76.67:7668?ttl=0&recv_buf_size=4194304";

struct BusConfig {
  std::string url = kDefaultLcmUrl;           // main port
  std::string bulk_url = kDefaultLcmBulkUrl;  // bulk port
  int64_t run_id = 0;                         // messages of other runs are dropped
  std::string sender;                         // header.sender of what we publish
  std::string key;  // the run's secret key (kKeyBytes), or empty: no MACs written or checked
  int queue_capacity = 10000;  // per-subscription LCM queue (LCM's default: 30)
};

/// An in-process bus (LCM's memq:// provider on both ports): only this process receives what it
/// publishes. For unit tests and benchmarks.
inline BusConfig InProcessBusConfig(int64_t run_id, std::string sender) {
  BusConfig c;
  c.url = c.bulk_url = "memq://";
  c.run_id = run_id;
  c.sender = std::move(sender);
  return c;
}

// What the bus dropped or lost, for the stats messages.
struct BusCounters {
  int64_t received = 0;         // messages handed to handlers
  int64_t malformed = 0;        // did not decode (foreign type, truncated, bad lengths)
  int64_t foreign = 0;          // another run's messages
  int64_t invalid = 0;          // decoded but failed Validate(), or the handler threw
  int64_t unauthenticated = 0;  // no MAC, or a wrong one
  int64_t replayed = 0;         // an older incarnation, or a sequence number already passed
  int64_t lost = 0;             // sequence gaps
  // Time spent signing and checking MACs (a monotonic clock; a preempted check counts its wait),
  // what authentication costs this process (bench_replay's pixel_replay_insert_cpu_mac row).
  int64_t mac_nanos = 0;

  int64_t dropped() const { return malformed + foreign + invalid + unauthenticated + replayed; }
};

enum class Port { kMain, kBulk };

class Bus {
 public:
  // Throws std::runtime_error naming the URL when LCM cannot start on it.
  explicit Bus(BusConfig config);
  Bus(const Bus&) = delete;
  Bus& operator=(const Bus&) = delete;
  ~Bus();

  // Fills msg->header and publishes. Returns false when LCM reported an error (it does not for
  // fragmented messages; see the README's transport notes).
  template <class Msg>
  bool Publish(const std::string& channel, Msg* msg, Port port = Port::kMain);

  // Publishes bytes as they are (for tools and tests that send foreign or broken messages).
  bool PublishRaw(const std::string& channel, const void* data, size_t size,
                  Port port = Port::kMain) {
    return lcm(port).publish(channel, data, static_cast<unsigned>(size)) == 0;
  }

  // Calls handler(msg) for every good message of type Msg on `channel`.
  template <class Msg>
  void Subscribe(const std::string& channel, std::function<void(const Msg&)> handler,
                 Port port = Port::kMain);

  // Waits at most timeout_ms (0: no wait) for traffic on either port, then dispatches every
  // pending message. Returns the number of messages dispatched.
  int Handle(int timeout_ms);

  const BusCounters& counters() const { return counters_; }
  const BusConfig& config() const { return config_; }
  // This bus's incarnation: when it started, in microseconds since the Unix epoch, and later than
  // any other Bus of this process (the MAC's nonces rely on it: common/message_auth.h).
  int64_t incarnation() const { return incarnation_; }

  // Copies the counters into a stats message's dropped_* and lost fields.
  template <class Stats>
  void FillCounters(Stats* s) const {
    s->dropped_malformed = counters_.malformed;
    s->dropped_foreign = counters_.foreign;
    s->dropped_invalid = counters_.invalid;
    s->dropped_unauthenticated = counters_.unauthenticated;
    s->dropped_replayed = counters_.replayed;
    s->lost = counters_.lost;
  }

 private:
  struct RawSubscription {
    std::string channel;
    std::function<void(const uint8_t*, size_t)> on_bytes;
    Bus* bus;
  };

  lcm::LCM& lcm(Port port) { return port == Port::kMain ? *main_ : *bulk_; }
  void SubscribeRaw(const std::string& channel, Port port,
                    std::function<void(const uint8_t*, size_t)> on_bytes);
  static void OnRaw(const lcm::ReceiveBuffer* rbuf, const std::string& channel,
                    RawSubscription* sub);
  // Signs an encoded message of ours published on `channel` (no-op without a key).
  bool Sign(const std::string& channel, uint8_t* data, size_t size, const rlmsg::header_t& header);
  struct SenderPosition {
    int64_t incarnation;
    int64_t seq;
  };
  // What one subscription has taken from each sender. Each subscription keeps its own, since LCM
  // hands every message to every subscription of its channel; only the channel's first
  // subscription counts gaps, so that a channel subscribed twice does not count them twice.
  struct Heard {
    bool counts_lost = false;
    std::map<std::string, SenderPosition> by_sender;
  };

  // Checks run id, MAC and freshness of a decoded message; returns false (and counts) when the
  // message is to be dropped.
  bool AcceptHeader(const std::string& channel, const rlmsg::header_t& header, const uint8_t* data,
                    size_t size, Heard* heard);
  void LogDrop(const std::string& channel, const char* kind, const char* reason);

  BusConfig config_;
  int64_t incarnation_;
  std::unique_ptr<MessageAuthenticator> auth_;  // null without a key
  std::unique_ptr<lcm::LCM> main_;
  std::unique_ptr<lcm::LCM> bulk_;
  std::vector<std::unique_ptr<RawSubscription>> subscriptions_;
  std::map<std::string, int64_t> publish_seq_;  // by channel
  std::set<std::string> subscribed_;            // channels with a subscription
  std::vector<uint8_t> encode_buffer_;
  BusCounters counters_;
  int64_t drops_logged_ = 0;
};

template <class Msg>
bool Bus::Publish(const std::string& channel, Msg* msg, Port port) {
  msg->header.run_id = config_.run_id;
  msg->header.sender = config_.sender;
  msg->header.seq = publish_seq_[channel]++;
  msg->header.utime = WallMicros();
  msg->header.incarnation = incarnation_;
  std::fill(std::begin(msg->header.mac), std::end(msg->header.mac), 0);
  const int size = msg->getEncodedSize();
  encode_buffer_.resize(static_cast<size_t>(size));
  if (msg->encode(encode_buffer_.data(), 0, size) != size) return false;
  if (!Sign(channel, encode_buffer_.data(), encode_buffer_.size(), msg->header)) return false;
  return lcm(port).publish(channel, encode_buffer_.data(), static_cast<unsigned>(size)) == 0;
}

template <class Msg>
void Bus::Subscribe(const std::string& channel, std::function<void(const Msg&)> handler,
                    Port port) {
  auto decoded = std::make_shared<Msg>();
  auto heard = std::make_shared<Heard>();
  heard->counts_lost = subscribed_.insert(channel).second;
  SubscribeRaw(channel, port,
               [this, channel, handler = std::move(handler), decoded, heard](const uint8_t* data,
                                                                             size_t size) {
                 Msg& msg = *decoded;
                 if (const char* why = Decode(data, size, &msg)) {
                   ++counters_.malformed;
                   LogDrop(channel, "malformed", why);
                   return;
                 }
                 if (!AcceptHeader(channel, msg.header, data, size, heard.get())) return;
                 if (const char* why = Validate(msg)) {
                   ++counters_.invalid;
                   LogDrop(channel, "invalid", why);
                   return;
                 }
                 try {
                   handler(msg);
                   ++counters_.received;
                 } catch (const std::exception& e) {
                   ++counters_.invalid;
                   LogDrop(channel, "invalid", e.what());
                 }
               });
}

}  // namespace rl
