// Authenticated messages: the run's secret key and the MAC in every message's header.
//
// A run has a 32-byte secret key, made by the launch script into the run folder (owner-only
// permissions) and read by every process from that file (--key-file), never from a command line.
// A publisher writes HMAC-SHA256, cut to its first 16 bytes, over the whole encoded message with
// header.mac zero into header.mac; a receiver recomputes it and drops the message when it differs
// (another key, a changed bit) or is all zero (no MAC). HMAC-SHA256 because it was the cheapest
// of the MACs we measured on our largest messages (bench_replay: `mac` rows); OpenSSL uses the
// CPU's SHA instructions where there are some.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

struct evp_mac_st;
struct evp_mac_ctx_st;

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

/// Signs and verifies encoded messages with one key. O(size) per call; no allocation after
/// construction. Not thread-safe (one per Bus).
class MessageAuthenticator {
 public:
  // Throws std::invalid_argument when the key is not kKeyBytes long, std::runtime_error when
  // OpenSSL cannot provide HMAC-SHA256.
  explicit MessageAuthenticator(const std::string& key);
  MessageAuthenticator(const MessageAuthenticator&) = delete;
  MessageAuthenticator& operator=(const MessageAuthenticator&) = delete;
  ~MessageAuthenticator();

  /// Writes the MAC of data[0, size) into data[mac_offset, mac_offset + kMacBytes), which must be
  /// zero. Returns false (and leaves data as it was) when the MAC does not fit or OpenSSL fails.
  bool Sign(uint8_t* data, size_t size, size_t mac_offset);

  /// nullptr when the MAC at mac_offset is right, else "no MAC" (all zero), "wrong MAC" or "no
  /// room for a MAC". Compares in constant time.
  const char* Verify(const uint8_t* data, size_t size, size_t mac_offset);

 private:
  bool Compute(const uint8_t* data, size_t size, size_t mac_offset, uint8_t* mac);

  std::string key_;
  evp_mac_st* mac_ = nullptr;
  evp_mac_ctx_st* ctx_ = nullptr;
};

}  // namespace rl
