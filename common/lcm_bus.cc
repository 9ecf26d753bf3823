#include "common/lcm_bus.h"

#include <poll.h>

#include <algorithm>
#include <atomic>
#include <charconv>
#include <cstdio>
#include <limits>
#include <stdexcept>
#include <tuple>

namespace rl {
namespace {

std::unique_ptr<lcm::LCM> OpenLcm(const std::string& url) {
  auto lcm = std::make_unique<lcm::LCM>(url);
  if (!lcm->good()) {
    throw std::runtime_error(
        "cannot start LCM on '" + url +
        "' (is there a multicast route? e.g. ip route add 224.0.0.0/4 dev lo)");
  }
  return lcm;
}

// Logs the first drops and then every 1000th, so a flood of bad messages cannot flood the log.
bool ShouldLog(int64_t n) { return n < 10 || n % 1000 == 0; }

// A start time in microseconds later than every earlier Bus's of this process.
int64_t NewIncarnation() {
  static std::atomic<int64_t> last{0};
  int64_t previous = last.load();
  int64_t next = 0;
  do {
    next = std::max(WallMicros(), previous + 1);
  } while (!last.compare_exchange_weak(previous, next));
  return next;
}

// Whether (incarnation, seq) a is later than b.
template <class A, class B>
bool Later(const A& a, const B& b) {
  return std::tie(a.incarnation, a.seq) > std::tie(b.incarnation, b.seq);
}

// LCM's limit on channel names is 63 bytes.
constexpr size_t kMaxChannelBytes = 63;

bool PrintableName(std::string_view s, size_t max) {
  return !s.empty() && s.size() <= max &&
         std::all_of(s.begin(), s.end(), [](char c) { return c >= '!' && c <= '~'; });
}

}  // namespace

const char* PortName(Port port) {
  switch (port) {
    case Port::kMain:
      return "main";
    case Port::kBulk:
      return "bulk";
    case Port::kSamples:
      return "samples";
  }
  return "?";
}

Port ChannelPort(std::string_view channel, std::string_view type, std::optional<Port> port) {
  const MessageInfo* info = FindChannel(channel);
  if (info == nullptr) return port.value_or(Port::kMain);
  if (!type.empty() && type != info->type) {
    throw std::invalid_argument(std::string(channel) + " carries " + std::string(info->type) +
                                ", not " + std::string(type) + " (common/channels.h)");
  }
  if (port && *port != info->port) {
    throw std::invalid_argument(std::string(channel) + " goes on the " + PortName(info->port) +
                                " port (common/channels.h)");
  }
  return info->port;
}

Bus::Bus(BusConfig config) : config_(std::move(config)), incarnation_(NewIncarnation()) {
  if (!ValidSenderName(config_.sender)) {
    throw std::invalid_argument("sender name '" + config_.sender +
                                "' is not 1 to 64 printable characters without spaces");
  }
  if (config_.max_message_age <= 0 || config_.max_clock_skew <= 0) {
    throw std::invalid_argument("the message age window and the clock skew must be > 0");
  }
  if (!config_.key.empty()) auth_ = std::make_unique<MessageAuthenticator>(config_.key);
  instances_.push_back(OpenLcm(config_.url));
  ports_[static_cast<int>(Port::kMain)] = instances_.back().get();
  instances_.push_back(OpenLcm(config_.bulk_url));
  ports_[static_cast<int>(Port::kBulk)] = instances_.back().get();
  if (config_.samples_url != config_.bulk_url) instances_.push_back(OpenLcm(config_.samples_url));
  ports_[static_cast<int>(Port::kSamples)] = instances_.back().get();
}

Bus::~Bus() = default;

void Bus::SubscribeRaw(const std::string& channel, Port port, int64_t fingerprint,
                       std::function<const char*(const uint8_t*, size_t)> decode,
                       std::function<void()> handle) {
  auto sub = std::make_unique<RawSubscription>();
  sub->channel = channel;
  sub->fingerprint = fingerprint;
  sub->decode = std::move(decode);
  sub->handle = std::move(handle);
  sub->bus = this;
  sub->counts_lost = std::none_of(subscriptions_.begin(), subscriptions_.end(),
                                  [&](const auto& s) { return s->channel == channel; });
  if (const auto it = restored_.find(channel); it != restored_.end()) sub->heard = it->second;
  // Through LCM's C API: its C++ one hands back a subscription it never made when the port
  // cannot be bound (another program's socket holds its UDP port: LCM prints "bind: ..."), and
  // that subscription crashes at first use.
  lcm_subscription_t* s =
      lcm_subscribe(lcm(port).getUnderlyingLCM(), channel.c_str(), &Bus::OnRaw, sub.get());
  if (s == nullptr) {
    throw std::runtime_error("cannot subscribe to " + channel + " on the " +
                             std::string(PortName(port)) + " port (" + PortUrl(port) +
                             "): is its UDP port held by another program?");
  }
  lcm_subscription_set_queue_capacity(s, config_.queue_capacity);
  subscriptions_.push_back(std::move(sub));
  subscribed_[static_cast<int>(port)] = true;
}

void Bus::OnRaw(const lcm_recv_buf_t* rbuf, const char* /*channel*/, void* user) {
  auto* sub = static_cast<RawSubscription*>(user);
  try {
    sub->bus->Receive(sub, static_cast<const uint8_t*>(rbuf->data), rbuf->data_size,
                      rbuf->recv_utime);
  } catch (...) {
    // Never let an exception cross LCM's C code.
    ++sub->bus->counters_.invalid;
  }
}

void Bus::Deliver(const std::string& channel, const uint8_t* data, size_t size,
                  int64_t recv_utime) {
  for (const auto& sub : subscriptions_) {
    if (sub->channel == channel) Receive(sub.get(), data, size, recv_utime);
  }
}

bool Bus::Sign(const std::string& channel, uint8_t* data, size_t size,
               const rlmsg::header_t& header) {
  if (auth_ == nullptr) return true;
  const int64_t start = MonoNanos();
  const bool ok = auth_->Sign(channel, data, size, MacOffset(header.sender.size()));
  counters_.mac_nanos += MonoNanos() - start;
  return ok;
}

void Bus::Receive(RawSubscription* sub, const uint8_t* data, size_t size, int64_t recv_utime) {
  const std::string& channel = sub->channel;
  WireHeader h;
  if (const char* why = ReadWireHeader(data, size, &h)) {
    Drop(channel, &counters_.malformed, "malformed", why);
    return;
  }
  if (h.fingerprint != sub->fingerprint) {
    Drop(channel, &counters_.malformed, "malformed", "another type (fingerprint)");
    return;
  }
  if (h.run_id != config_.run_id) {
    Drop(channel, &counters_.foreign, "foreign", "another run's id");
    return;
  }
  if (auth_ != nullptr) {
    const int64_t start = MonoNanos();
    const char* why = auth_->Verify(channel, data, size, h.mac_offset);
    counters_.mac_nanos += MonoNanos() - start;
    if (why != nullptr) {
      Drop(channel, &counters_.unauthenticated, "unauthenticated", why);
      return;
    }
  }
  if (h.seq < 0 || h.incarnation < 0) {
    Drop(channel, &counters_.invalid, "invalid", "a negative sequence number or incarnation");
    return;
  }
  if (const char* why = Stale(h, recv_utime)) {
    Drop(channel, &counters_.stale, "stale", why);
    return;
  }
  if (const char* why = Replayed(*sub, h, recv_utime)) {
    Drop(channel, &counters_.replayed, "replayed", why);
    return;
  }
  if (const char* why = sub->decode(data, size)) {
    Drop(channel, &counters_.malformed, "malformed", why);
    return;
  }
  // A decoded message takes its sequence number, also when Validate() refuses it: the same
  // bytes again are replayed.
  Take(sub, h);
  sub->handle();
}

const char* Bus::Stale(const WireHeader& h, int64_t recv_utime) const {
  // recv_utime is a clock reading, far from the ends of int64: no overflow.
  if (h.utime < recv_utime - config_.max_message_age) return "older than the message age window";
  if (h.utime > recv_utime + config_.max_clock_skew) return "from beyond the allowed clock skew";
  if (h.incarnation > h.utime + config_.max_clock_skew) {
    return "an incarnation later than its publication time";
  }
  return nullptr;
}

const char* Bus::Replayed(const RawSubscription& sub, const WireHeader& h,
                          int64_t recv_utime) const {
  const auto it = sub.heard.find(h.sender);
  if (it == sub.heard.end()) return nullptr;
  const Position& last = it->second;
  // A newer incarnation is the sender restarted: its sequence starts again. A position older
  // than the window guards nothing (whatever it would refuse is stale), so it yields to any
  // message: a forged later incarnation or sequence number is forgotten that way.
  if (h.incarnation > last.incarnation || last.utime < recv_utime - config_.max_message_age) {
    return nullptr;
  }
  if (h.incarnation < last.incarnation) return "an older incarnation of its sender";
  return h.seq > last.seq ? nullptr : "a sequence number already passed";
}

void Bus::Take(RawSubscription* sub, const WireHeader& h) {
  SenderPositions& heard = sub->heard;
  const Position next{h.incarnation, h.seq, h.utime, false};
  auto it = heard.find(h.sender);
  if (it == heard.end()) {
    if (heard.size() >= kMaxSenders) {
      heard.erase(std::min_element(heard.begin(), heard.end(), [](const auto& a, const auto& b) {
        return a.second.utime < b.second.utime;
      }));
    }
    heard.emplace(std::string(h.sender), next);
    return;
  }
  Position& last = it->second;
  if (h.incarnation == last.incarnation && h.seq > last.seq && sub->counts_lost && !last.restored) {
    // Both are >= 0, so the gap cannot overflow; the sum saturates (a gap of 2^62 is a forgery
    // by a holder of the key, or on a bus without one).
    const int64_t gap = h.seq - last.seq - 1;
    counters_.lost = gap > std::numeric_limits<int64_t>::max() - counters_.lost
                         ? std::numeric_limits<int64_t>::max()
                         : counters_.lost + gap;
  }
  last = next;
}

void Bus::Drop(const std::string& channel, int64_t* counter, const char* kind, const char* reason) {
  ++*counter;
  if (ShouldLog(drops_logged_++)) {
    std::fprintf(stderr, "[%s] dropped a %s message on %s: %s\n", config_.sender.c_str(), kind,
                 channel.c_str(), reason);
  }
}

std::vector<StreamPosition> Bus::Positions() const {
  // The newest per (channel, sender): the subscriptions', or the restored ones of channels
  // without a subscription.
  std::map<std::pair<std::string, std::string>, Position> newest;
  auto take = [&newest](const std::string& channel, const SenderPositions& heard) {
    for (const auto& [sender, p] : heard) {
      auto [it, fresh] = newest.try_emplace({channel, sender}, p);
      if (!fresh && Later(p, it->second)) it->second = p;
    }
  };
  for (const auto& sub : subscriptions_) take(sub->channel, sub->heard);
  for (const auto& [channel, heard] : restored_) {
    const std::string& name = channel;  // (a lambda may not capture a structured binding)
    const bool subscribed = std::any_of(subscriptions_.begin(), subscriptions_.end(),
                                        [&name](const auto& s) { return s->channel == name; });
    if (!subscribed) take(channel, heard);
  }
  const int64_t oldest = WallMicros() - config_.max_message_age;
  std::vector<StreamPosition> out;
  for (const auto& [key, p] : newest) {
    if (p.utime >= oldest) out.push_back({key.first, key.second, p.incarnation, p.seq, p.utime});
  }
  return out;
}

void Bus::RestorePositions(const std::vector<StreamPosition>& positions) {
  auto merge = [](SenderPositions* heard, const StreamPosition& p) {
    const Position restored{p.incarnation, p.seq, p.utime, true};
    auto [it, fresh] = heard->try_emplace(p.sender, restored);
    if (!fresh && Later(restored, it->second)) it->second = restored;
  };
  for (const StreamPosition& p : positions) {
    merge(&restored_[p.channel], p);
    for (const auto& sub : subscriptions_) {
      if (sub->channel == p.channel) merge(&sub->heard, p);
    }
  }
}

std::string FormatPositions(const std::vector<StreamPosition>& positions) {
  std::string text;
  for (const StreamPosition& p : positions) {
    text += p.channel + ' ' + p.sender + ' ' + std::to_string(p.incarnation) + ' ' +
            std::to_string(p.seq) + ' ' + std::to_string(p.utime) + '\n';
  }
  return text;
}

std::vector<StreamPosition> ParsePositions(std::string_view text) {
  std::vector<StreamPosition> out;
  size_t line = 0;
  while (!text.empty()) {
    ++line;
    const size_t end = text.find('\n');
    if (end == std::string_view::npos) {
      throw std::runtime_error("bus positions: line " + std::to_string(line) + " has no end");
    }
    std::string_view rest = text.substr(0, end);
    text.remove_prefix(end + 1);
    auto fail = [line](const char* why) {
      throw std::runtime_error("bus positions: line " + std::to_string(line) + ": " + why);
    };
    if (out.size() >= kMaxStoredPositions) fail("more positions than a bus keeps");
    std::string_view fields[5];
    for (std::string_view& f : fields) {
      const size_t space = rest.find(' ');
      f = rest.substr(0, space);
      rest = space == std::string_view::npos ? std::string_view() : rest.substr(space + 1);
    }
    if (!rest.empty()) fail("more than five fields");
    if (!PrintableName(fields[0], kMaxChannelBytes)) fail("not a channel name");
    if (!ValidSenderName(fields[1])) fail("not a sender name");
    int64_t numbers[3] = {};
    for (int k = 0; k < 3; ++k) {
      const std::string_view f = fields[2 + k];
      const auto [ptr, ec] = std::from_chars(f.data(), f.data() + f.size(), numbers[k]);
      if (f.empty() || ec != std::errc() || ptr != f.data() + f.size()) fail("not a number");
    }
    if (numbers[0] < 0 || numbers[1] < 0) fail("a negative incarnation or sequence number");
    out.push_back(
        {std::string(fields[0]), std::string(fields[1]), numbers[0], numbers[1], numbers[2]});
  }
  return out;
}

int Bus::Handle(int timeout_ms) {
  // Only the ports with a subscription: LCM's udpm binds a port and joins its group when asked
  // for its descriptor, subscribed or not. (With none, poll() just waits out the timeout.)
  // A port that shares another's instance is polled once.
  pollfd fds[kNumPorts];
  lcm::LCM* ports[kNumPorts];
  nfds_t count = 0;
  for (int k = 0; k < kNumPorts; ++k) {
    if (!subscribed_[k] || std::find(ports, ports + count, ports_[k]) != ports + count) continue;
    ports[count] = ports_[k];
    fds[count] = {ports[count]->getFileno(), POLLIN, 0};
    ++count;
  }
  int dispatched = 0;
  int wait = timeout_ms;
  // Dispatch until the queues are empty; bounded so that a flood cannot starve the caller.
  for (int round = 0; round < 100000; ++round) {
    if (poll(fds, count, wait) <= 0) break;
    wait = 0;
    for (nfds_t k = 0; k < count; ++k) {
      if (fds[k].revents & POLLIN) {
        ports[k]->handle();
        ++dispatched;
      }
    }
  }
  return dispatched;
}

}  // namespace rl
