#include "common/lcm_bus.h"

#include <poll.h>

#include <algorithm>
#include <atomic>
#include <cstdio>
#include <limits>
#include <stdexcept>

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

}  // namespace

namespace {

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

}  // namespace

Bus::Bus(BusConfig config) : config_(std::move(config)), incarnation_(NewIncarnation()) {
  if (!config_.key.empty()) auth_ = std::make_unique<MessageAuthenticator>(config_.key);
  main_ = OpenLcm(config_.url);
  bulk_ = OpenLcm(config_.bulk_url);
}

Bus::~Bus() = default;

void Bus::SubscribeRaw(const std::string& channel, Port port,
                       std::function<void(const uint8_t*, size_t)> on_bytes) {
  auto sub = std::make_unique<RawSubscription>(RawSubscription{channel, std::move(on_bytes), this});
  lcm::Subscription* s =
      lcm(port).subscribeFunction<RawSubscription*>(channel, &Bus::OnRaw, sub.get());
  if (s == nullptr) throw std::runtime_error("cannot subscribe to " + channel);
  s->setQueueCapacity(config_.queue_capacity);
  subscriptions_.push_back(std::move(sub));
}

void Bus::OnRaw(const lcm::ReceiveBuffer* rbuf, const std::string& /*channel*/,
                RawSubscription* sub) {
  try {
    sub->on_bytes(static_cast<const uint8_t*>(rbuf->data), rbuf->data_size);
  } catch (...) {
    // Never let an exception cross LCM's C code.
    ++sub->bus->counters_.invalid;
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

bool Bus::AcceptHeader(const std::string& channel, const rlmsg::header_t& header,
                       const uint8_t* data, size_t size, Heard* heard) {
  if (header.run_id != config_.run_id) {
    ++counters_.foreign;
    LogDrop(channel, "foreign", "another run's id");
    return false;
  }
  if (auth_ != nullptr) {
    const int64_t start = MonoNanos();
    const char* why = auth_->Verify(channel, data, size, MacOffset(header.sender.size()));
    counters_.mac_nanos += MonoNanos() - start;
    if (why != nullptr) {
      ++counters_.unauthenticated;
      LogDrop(channel, "unauthenticated", why);
      return false;
    }
  }
  if (header.seq < 0 || header.incarnation < 0) {
    ++counters_.invalid;
    LogDrop(channel, "invalid", "a negative sequence number or incarnation");
    return false;
  }
  // Only what comes after what we heard from this incarnation is fresh; a newer incarnation is
  // the sender restarted, and its sequence starts again.
  auto [it, inserted] =
      heard->by_sender.try_emplace(header.sender, SenderPosition{header.incarnation, header.seq});
  SenderPosition& last = it->second;
  if (inserted) return true;
  if (header.incarnation > last.incarnation) {
    last = {header.incarnation, header.seq};
    return true;
  }
  if (header.incarnation < last.incarnation || header.seq <= last.seq) {
    ++counters_.replayed;
    LogDrop(channel, "replayed",
            header.incarnation < last.incarnation ? "an older incarnation of its sender"
                                                  : "a sequence number already passed");
    return false;
  }
  // Both are >= 0, so the gap cannot overflow; the sum saturates (a gap of 2^62 is a forgery by a
  // holder of the key, or on a bus without one).
  const int64_t gap = header.seq - last.seq - 1;
  if (heard->counts_lost) {
    counters_.lost = gap > std::numeric_limits<int64_t>::max() - counters_.lost
                         ? std::numeric_limits<int64_t>::max()
                         : counters_.lost + gap;
  }
  last.seq = header.seq;
  return true;
}

void Bus::LogDrop(const std::string& channel, const char* kind, const char* reason) {
  if (ShouldLog(drops_logged_++)) {
    std::fprintf(stderr, "[%s] dropped a %s message on %s: %s\n", config_.sender.c_str(), kind,
                 channel.c_str(), reason);
  }
}

int Bus::Handle(int timeout_ms) {
  pollfd fds[2] = {{main_->getFileno(), POLLIN, 0}, {bulk_->getFileno(), POLLIN, 0}};
  int dispatched = 0;
  int wait = timeout_ms;
  // Dispatch until both queues are empty; bounded so that a flood cannot starve the caller.
  for (int round = 0; round < 100000; ++round) {
    if (poll(fds, 2, wait) <= 0) break;
    wait = 0;
    if (fds[0].revents & POLLIN) {
      main_->handle();
      ++dispatched;
    }
    if (fds[1].revents & POLLIN) {
      bulk_->handle();
      ++dispatched;
    }
  }
  return dispatched;
}

}  // namespace rl
