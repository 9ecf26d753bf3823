// Bus: the one way our processes talk LCM.
//
// It owns an LCM instance for each port of the run (common/channels.h): the main port (small,
// high-rate messages), the bulk port (weights) and the samples port (the replay's sample replies
// to the learner), so that bulk traffic never starves the rest and the actors never receive the
// sample replies. Publish() fills the header (run id, sender, incarnation, per-channel sequence
// number, time) and, when the run has a key, the MAC (common/message_auth.h). Subscribe() installs
// a typed handler behind the checks, and a message reaches the handler only when it passes every
// one, in this order, each drop counted by its reason:
//   malformed        its header cannot be read from the raw bytes (too short, a sender name that
//                    is empty, over 64 bytes or not printable), it is another type (fingerprint),
//                    or later it does not decode (torn or forged lengths: Prescan, lcm-gen)
//   foreign          another run's id
//   unauthenticated  no MAC or a wrong one (with a key; a bus without one checks none)
//   invalid          a negative sequence number or incarnation
//   stale            its time (header.utime) is more than max_message_age before the packet
//                    reached this host, or more than max_clock_skew after it; or its incarnation
//                    is later than its time (plus the skew): no process publishes before it starts
//   replayed         an incarnation of its sender older than one heard, or a sequence number of
//                    the sender's incarnation on this channel already passed
//   malformed        (as above) the decoder refuses it (Prescan, then lcm-gen's decoder)
//   invalid          fails Validate() (or the handler threw)
// The header is read from the raw bytes and every check up to the replay check runs before any
// decoding, so a forged, stale or replayed message costs its MAC check (one GMAC pass over its
// bytes, no key derivation: message_auth.h) and nothing more. A message that decodes takes its
// sender's position, also when Validate() then refuses it.
//
// Freshness: "the packet reached this host" is LCM's receive time (the kernel's timestamp of the
// packet, taken before any queueing in this process), so a process busy for minutes (an evaluator
// scoring, a learner writing a checkpoint) never ages the messages waiting in its queue. Each
// subscription keeps the last position (incarnation, sequence number, time) it accepted from each
// sender (of at most kMaxSenders senders; past them, the one heard longest ago goes); a position
// whose time is older than max_message_age guards nothing any more (every message it would
// refuse is stale) and gives way to the sender's next message, so a forged message with a later
// incarnation or a huge sequence number silences its sender for at most max_message_age +
// max_clock_skew. Gaps in a sender incarnation's sequence are counted as lost; a newer
// incarnation (a restarted sender) starts a new sequence. Positions() / LoadPositions() export
// and restore them, so that a restarted process (the replay from its snapshot, the learner from
// its state) still refuses recorded traffic older than its saved state.
//
// Handlers must not throw; if one does, the exception is caught, logged and counted as invalid.
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
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "common/channels.h"
#include "common/clock.h"
#include "common/message_auth.h"
#include "common/messages.h"

namespace rl {

// Default URLs: one multicast port per traffic class, 8 MiB receive buffers (see README).
inline constexpr char kDefaultLcmUrl[] = "udpm://239.255.76.67:7667?ttl=0&recv_buf_size=4194304";
inline constexpr char kDefaultLcmBulkUrl[] =
    "udpm://239.255.76.67:7668?ttl=0&recv_buf_size=4194304";
inline constexpr char kDefaultLcmSamplesUrl[] =
    "udpm://239.255.76.67:7669?ttl=0&recv_buf_size=4194304";

// The freshness window's defaults (BusConfig, --max-message-age and --max-clock-skew). A message's
// age is its sender's clock at publication against this host's at the packet's arrival, before
// any queueing in the receiving process; what is left in it is the network (milliseconds on a
// LAN) and the difference between two hosts' clocks, milliseconds under NTP or chrony, which
// cluster nodes run. 60 s behind and 10 s ahead leave room for a node whose clock has drifted for
// a few days with neither, and still refuse a recording played back a minute after it was made.
inline constexpr int64_t kDefaultMaxMessageAgeMicros = 60'000'000;
inline constexpr int64_t kDefaultMaxClockSkewMicros = 10'000'000;

struct BusConfig {
  std::string url = kDefaultLcmUrl;           // main port
  std::string bulk_url = kDefaultLcmBulkUrl;  // bulk port
  // Samples port; the bulk port's URL shares the bulk port's LCM instance (a TCP hub's run, where
  // the hub forwards a channel only to its subscribers).
  std::string samples_url = kDefaultLcmSamplesUrl;
  int64_t run_id = 0;  // messages of other runs are dropped
  std::string sender;  // header.sender of what we publish
  std::string key;     // the run's secret key (kKeyBytes), or empty: no MACs written or checked
  int queue_capacity = 10000;  // per-subscription LCM queue (LCM's default: 30)
  // Freshness window (see the top of this file), microseconds, both > 0.
  int64_t max_message_age = kDefaultMaxMessageAgeMicros;
  int64_t max_clock_skew = kDefaultMaxClockSkewMicros;
};

/// An in-process bus (LCM's memq:// provider on every port): only this process receives what it
/// publishes. For unit tests and benchmarks.
inline BusConfig InProcessBusConfig(int64_t run_id, std::string sender) {
  BusConfig c;
  c.url = c.bulk_url = c.samples_url = "memq://";
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
  int64_t stale = 0;            // outside the freshness window, or an incarnation after its time
  int64_t replayed = 0;         // an older incarnation, or a sequence number already passed
  int64_t lost = 0;             // sequence gaps
  // Time spent signing and checking MACs (a monotonic clock; a preempted check counts its wait),
  // what authentication costs this process (bench_replay's pixel_replay_insert_cpu_mac row).
  int64_t mac_nanos = 0;

  int64_t dropped() const {
    return malformed + foreign + invalid + unauthenticated + stale + replayed;
  }
};

// The last message a subscription accepted from one sender on one channel (Bus::Positions()).
struct StreamPosition {
  std::string channel;
  std::string sender;
  int64_t incarnation = 0;
  int64_t seq = 0;
  int64_t utime = 0;  // its header.utime
};

/// Positions as text, one per line: "CHANNEL SENDER INCARNATION SEQ UTIME" (for state files).
std::string FormatPositions(const std::vector<StreamPosition>& positions);
/// The inverse. Throws std::runtime_error naming the line and what is wrong: not five fields, a
/// channel or sender name that is empty, too long or not printable, a number that is not one or
/// negative (incarnation, seq), or more than kMaxStoredPositions lines.
std::vector<StreamPosition> ParsePositions(std::string_view text);
inline constexpr size_t kMaxStoredPositions = 65536;

/// "main", "bulk" or "samples".
const char* PortName(Port port);

/// The port a message of `type` (lcm-gen's name) goes on when published or subscribed on
/// `channel`: the channel's port in RL_MESSAGES (common/channels.h), or `port` (the main one if
/// none) for a channel of no run message. Throws std::invalid_argument naming the channel when the
/// table gives the channel another type (pass an empty type to skip this check, for raw bytes) or
/// another port than `port`: a programming error, caught by the first test that runs it.
Port ChannelPort(std::string_view channel, std::string_view type, std::optional<Port> port);

class Bus {
 public:
  // Throws std::runtime_error naming the URL when LCM cannot start on it, std::invalid_argument
  // when the sender name is not ValidSenderName() or the freshness window is not positive.
  explicit Bus(BusConfig config);
  Bus(const Bus&) = delete;
  Bus& operator=(const Bus&) = delete;
  ~Bus();

  // Fills msg->header and publishes, on the channel's port (ChannelPort(): a channel of
  // common/channels.h takes only its type). Returns false when LCM reported an error (it does not
  // for fragmented messages; see the README's transport notes).
  template <class Msg>
  bool Publish(const std::string& channel, Msg* msg, std::optional<Port> port = std::nullopt);

  // Publishes bytes as they are (for tools and tests that send foreign or broken messages), on
  // the channel's port (ChannelPort() without the type check).
  bool PublishRaw(const std::string& channel, const void* data, size_t size,
                  std::optional<Port> port = std::nullopt) {
    return lcm(ChannelPort(channel, {}, port))
               .publish(channel, data, static_cast<unsigned>(size)) == 0;
  }

  // Calls handler(msg) for every good message of type Msg on `channel`, on the channel's port
  // (ChannelPort(): a channel of common/channels.h takes only its type). The subscription starts
  // from the positions restored for its channel (LoadPositions()). Each message of the channel
  // decodes into one object that the subscription keeps, so its arrays are allocated once; a
  // handler that keeps a message swaps its contents out (std::swap with an object of its own,
  // best one used before) rather than copying them, and the next message decodes into what it
  // left there.
  template <class Msg>
  void Subscribe(const std::string& channel, std::function<void(Msg&)> handler,
                 std::optional<Port> port = std::nullopt);

  // Handles `size` bytes as if LCM had received them on `channel` at recv_utime (microseconds
  // since the Unix epoch): every subscription of the channel checks them (for tests, benchmarks
  // and fuzzing, which need no transport and choose the receive time).
  void Deliver(const std::string& channel, const uint8_t* data, size_t size, int64_t recv_utime);

  // The last position accepted from each sender on each channel, the newest over a channel's
  // subscriptions, with those restored for channels not subscribed; without positions that have
  // aged out of the window. Sorted by channel and sender.
  std::vector<StreamPosition> Positions() const;
  // Makes every subscription of a position's channel, now and later, refuse what is not newer
  // than it (a position it holds already wins when newer). Gaps after a restored position are not
  // counted as lost.
  void RestorePositions(const std::vector<StreamPosition>& positions);
  std::string SavePositions() const { return FormatPositions(Positions()); }
  // ParsePositions(text), then RestorePositions (throws as ParsePositions does).
  void LoadPositions(std::string_view text) { RestorePositions(ParsePositions(text)); }

  // Waits at most timeout_ms (0: no wait) for traffic on the ports this bus subscribes on, then
  // dispatches every pending message. Returns the number of messages dispatched. A port without
  // a subscription is never read, so LCM never joins it: a process with no use for the bulk or
  // the samples port does not copy every weight broadcast or sample reply of the run out of the
  // kernel only to drop it.
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
    s->dropped_stale = counters_.stale;
    s->dropped_replayed = counters_.replayed;
    s->lost = counters_.lost;
  }

 private:
  // A sender's last accepted message on one subscription.
  struct Position {
    int64_t incarnation = 0;
    int64_t seq = 0;
    int64_t utime = 0;
    bool restored = false;  // from LoadPositions, nothing heard since: no gap counted after it
  };
  using SenderPositions = std::map<std::string, Position, std::less<>>;  // by sender
  // Senders whose positions one subscription keeps; past it, the one heard longest ago goes.
  static constexpr size_t kMaxSenders = 1024;

  struct RawSubscription {
    std::string channel;
    int64_t fingerprint = 0;  // the type's
    // Decodes a message that passed the header checks into the subscription's object (nullptr,
    // or why it does not decode); then validates it and hands it to the handler.
    std::function<const char*(const uint8_t*, size_t)> decode;
    std::function<void()> handle;
    Bus* bus = nullptr;
    // Only the channel's first subscription counts gaps, so that a channel subscribed twice does
    // not count them twice.
    bool counts_lost = false;
    SenderPositions heard;
  };

  lcm::LCM& lcm(Port port) { return *ports_[static_cast<int>(port)]; }
  const std::string& PortUrl(Port port) const {
    return port == Port::kMain   ? config_.url
           : port == Port::kBulk ? config_.bulk_url
                                 : config_.samples_url;
  }
  void SubscribeRaw(const std::string& channel, Port port, int64_t fingerprint,
                    std::function<const char*(const uint8_t*, size_t)> decode,
                    std::function<void()> handle);
  static void OnRaw(const lcm_recv_buf_t* rbuf, const char* channel, void* sub);
  // Every check (see the top of this file), decoding, and the handler.
  void Receive(RawSubscription* sub, const uint8_t* data, size_t size, int64_t recv_utime);
  // Why a message is stale, or nullptr.
  const char* Stale(const WireHeader& h, int64_t recv_utime) const;
  // Why a message is replayed (not newer than its sender's position, which has not aged out), or
  // nullptr. Changes nothing.
  const char* Replayed(const RawSubscription& sub, const WireHeader& h, int64_t recv_utime) const;
  // Takes a message's position (one Replayed() passed, and that decoded), counting a gap in its
  // sender incarnation's sequence as lost.
  void Take(RawSubscription* sub, const WireHeader& h);
  // Signs an encoded message of ours published on `channel` (no-op without a key).
  bool Sign(const std::string& channel, uint8_t* data, size_t size, const rlmsg::header_t& header);
  void Drop(const std::string& channel, int64_t* counter, const char* kind, const char* reason);

  BusConfig config_;
  int64_t incarnation_;
  std::unique_ptr<MessageAuthenticator> auth_;        // null without a key
  std::vector<std::unique_ptr<lcm::LCM>> instances_;  // one per distinct URL
  lcm::LCM* ports_[kNumPorts] = {};                   // by Port: its instance
  std::vector<std::unique_ptr<RawSubscription>> subscriptions_;
  bool subscribed_[kNumPorts] = {};                               // by Port: a subscription on it
  std::map<std::string, int64_t> publish_seq_;                    // by channel
  std::map<std::string, SenderPositions, std::less<>> restored_;  // by channel (LoadPositions)
  std::vector<uint8_t> encode_buffer_;
  BusCounters counters_;
  int64_t drops_logged_ = 0;
};

template <class Msg>
bool Bus::Publish(const std::string& channel, Msg* msg, std::optional<Port> port) {
  const Port checked = ChannelPort(channel, Msg::getTypeName(), port);
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
  return lcm(checked).publish(channel, encode_buffer_.data(), static_cast<unsigned>(size)) == 0;
}

template <class Msg>
void Bus::Subscribe(const std::string& channel, std::function<void(Msg&)> handler,
                    std::optional<Port> port) {
  auto decoded = std::make_shared<Msg>();
  SubscribeRaw(
      channel, ChannelPort(channel, Msg::getTypeName(), port), Msg::getHash(),
      [decoded](const uint8_t* data, size_t size) { return Decode(data, size, decoded.get()); },
      [this, channel, handler = std::move(handler), decoded] {
        Msg& msg = *decoded;
        if (const char* why = Validate(msg)) {
          Drop(channel, &counters_.invalid, "invalid", why);
          return;
        }
        try {
          handler(msg);
          ++counters_.received;
        } catch (const std::exception& e) {
          Drop(channel, &counters_.invalid, "invalid", e.what());
        }
      });
}

}  // namespace rl
