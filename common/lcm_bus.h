// Bus: the one way our processes talk LCM.
//
// It owns two LCM instances, one for the main port (small, high-rate messages) and one for the
// bulk port (weights, sample replies), so that bulk traffic never starves the rest. Publish()
// fills the header (run id, sender, per-channel sequence number, time). Subscribe() installs a
// typed handler behind a checking decoder: a message that does not decode (foreign type, torn or
// forged lengths) is counted as malformed, one of another run as foreign, one that fails
// Validate() as invalid, and none of them reaches the handler. Sequence gaps per sender and
// channel are counted as lost. Handlers must not throw; if one does, the exception is caught,
// logged and counted as invalid.
//
// Not thread-safe: one thread constructs, publishes and calls Handle().
#pragma once

#include <lcm/lcm-cpp.hpp>

#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "common/clock.h"
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
  int queue_capacity = 10000;                 // per-subscription LCM queue (LCM's default: 30)
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
  int64_t received = 0;   // messages handed to handlers
  int64_t malformed = 0;  // did not decode (foreign type, truncated, bad lengths)
  int64_t foreign = 0;    // another run's messages
  int64_t invalid = 0;    // decoded but failed Validate(), or the handler threw
  int64_t lost = 0;       // sequence gaps
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

  // Copies the counters into a stats message's dropped_* and lost fields.
  template <class Stats>
  void FillCounters(Stats* s) const {
    s->dropped_malformed = counters_.malformed;
    s->dropped_foreign = counters_.foreign;
    s->dropped_invalid = counters_.invalid;
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
  // Checks run id and sequence; returns false (and counts) when the message is to be dropped.
  bool AcceptHeader(const std::string& channel, const rlmsg::header_t& header);
  void LogDrop(const std::string& channel, const char* kind, const char* reason);

  BusConfig config_;
  std::unique_ptr<lcm::LCM> main_;
  std::unique_ptr<lcm::LCM> bulk_;
  std::vector<std::unique_ptr<RawSubscription>> subscriptions_;
  std::map<std::string, int64_t> publish_seq_;                       // by channel
  std::map<std::pair<std::string, std::string>, int64_t> last_seq_;  // by channel and sender
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
  const int size = msg->getEncodedSize();
  encode_buffer_.resize(static_cast<size_t>(size));
  if (msg->encode(encode_buffer_.data(), 0, size) != size) return false;
  return lcm(port).publish(channel, encode_buffer_.data(), static_cast<unsigned>(size)) == 0;
}

template <class Msg>
void Bus::Subscribe(const std::string& channel, std::function<void(const Msg&)> handler,
                    Port port) {
  auto decoded = std::make_shared<Msg>();
  SubscribeRaw(
      channel, port,
      [this, channel, handler = std::move(handler), decoded](const uint8_t* data, size_t size) {
        Msg& msg = *decoded;
        if (const char* why = Decode(data, size, &msg)) {
          ++counters_.malformed;
          LogDrop(channel, "malformed", why);
          return;
        }
        if (!AcceptHeader(channel, msg.header)) return;
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
