// Authenticated messages: the run's secret key and the MAC in every message's header.
//
// A run has a 32-byte secret key, made by the launch script into the run folder (owner-only
// permissions) and read by every process from that file (--key-file), never from a command line.
// A publisher writes a 16-byte MAC over the whole encoded message, with header.mac zero, into
// header.mac; a receiver recomputes it and drops the message when it differs (another key, a
// changed bit, another channel) or is all zero (no MAC).
//
// The MAC is AES-256-GMAC (common/gmac.h: AES-GCM over the message as associated data, nothing
// encrypted), the cheapest of the MACs we measured on our largest messages (bench_replay `mac`
// rows). GMAC must never see one nonce twice under one key, so each message is keyed by what
// already makes it unique in a run, and nothing else:
//   key   = HMAC-SHA256(run key, "rl-gmac-v1" | channel | header.sender | header.incarnation)
//   nonce = header.seq (8 bytes big-endian) | 4 zero bytes
// A Bus numbers each channel's messages 0, 1, 2, ... within one incarnation (its start time in
// microseconds, unique in a process), so a nonce repeats under one key only if two processes with
// the same sender name start within the same microsecond, which the launch script's names rule
// out (and freshness checks need anyway). A replayed message carries its original nonce and MAC:
// it verifies, and it is the Bus's freshness check that drops it. The key of a channel, sender and
// incarnation is derived once and kept (a bounded cache), so a message costs one GHASH pass.
#pragma once

#include <cstddef>
#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <string_view>

#include "common/gmac.h"

namespace rl {

inline constexpr size_t kKeyBytes = 32;
inline constexpr size_t kMacBytes = 16;

/// Reads a run's key file: a regular file of exactly kKeyBytes bytes that only its owner may read
/// or write (mode 0600 or 0400). Throws std::runtime_error naming the file and what is wrong.
std::string ReadKeyFile(const std::string& path);

/// Where header.mac starts in an encoded message whose first field is header_t (8-byte
/// fingerprint, run_id, sender, seq, utime, incarnation, mac) with a sender of `sender_length`
/// bytes.
constexpr size_t MacOffset(size_t sender_length) { return 8 + 8 + 4 + sender_length + 1 + 24; }

/// Signs and verifies encoded messages with one run key. Reads the sender, sequence number and
/// incarnation from the header bytes before `mac_offset` (as MacOffset() lays them out). O(size)
/// per call; no allocation after a (channel, sender)'s first message; at most kMaxStreams keys
/// kept, past which a key is derived per message. Not thread-safe (one per Bus).
class MessageAuthenticator {
 public:
  static constexpr size_t kMaxStreams = 256;

  // Throws std::invalid_argument when the key is not kKeyBytes long, std::runtime_error when
  // OpenSSL cannot provide AES-256-GCM or HMAC-SHA256.
  explicit MessageAuthenticator(const std::string& key);
  MessageAuthenticator(const MessageAuthenticator&) = delete;
  MessageAuthenticator& operator=(const MessageAuthenticator&) = delete;
  ~MessageAuthenticator();

  /// Writes the MAC of data[0, size), published on `channel`, into data[mac_offset, mac_offset +
  /// kMacBytes), which must be zero. Returns false (and leaves data as it was) when the header
  /// has no room for a MAC or OpenSSL fails. The caller must never sign two different messages
  /// with one (channel, sender, incarnation, seq): that would reveal the stream's hash key.
  bool Sign(std::string_view channel, uint8_t* data, size_t size, size_t mac_offset);

  /// nullptr when the MAC at mac_offset is right for `channel`, else "no MAC" (all zero), "wrong
  /// MAC" or "no room for a MAC". Compares in constant time. A failed check changes no kept key.
  const char* Verify(std::string_view channel, const uint8_t* data, size_t size, size_t mac_offset);

 private:
  // A derived key, ready: one (channel, sender)'s newest incarnation.
  struct Stream {
    int64_t incarnation = 0;
    std::unique_ptr<Gmac> gmac;
  };

  // The key for the message's (channel, sender, incarnation): a kept one, or one derived into
  // scratch_ (then *derived is true). nullptr when OpenSSL fails.
  Gmac* KeyFor(std::string_view channel, const uint8_t* data, size_t mac_offset, bool* derived);
  // Keeps scratch_'s key for the message's stream (when its incarnation is the newest and there
  // is room), taking a new scratch_.
  void Keep(const uint8_t* data, size_t mac_offset);
  static bool Compute(Gmac* gmac, const uint8_t* data, size_t size, size_t mac_offset,
                      uint8_t* mac);

  std::string key_;
  std::map<std::string, Stream, std::less<>> streams_;  // by channel '\0' sender
  std::string lookup_;                                  // the last message's stream name
  std::unique_ptr<Gmac> scratch_;
};

}  // namespace rl
