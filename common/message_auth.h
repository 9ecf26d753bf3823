// Authenticated messages: the run's secret key and the MAC in every message's header.
//
// A run has a 32-byte secret key, made by the launch script into the run folder (owner-only
// permissions) and read by every process from that file (--key-file), never from a command line.
// A publisher writes a 16-byte MAC over the whole encoded message, with header.mac zero, into
// header.mac; a receiver recomputes it and drops the message when it differs (another key, a
// changed bit, another channel) or is all zero (no MAC).
//
// The MAC is AES-256-GMAC, computed by OpenSSL: AES-256-GCM over the message as associated data,
// nothing encrypted. GMAC must never see one nonce twice under one key; what makes a message
// unique in a run is its channel, sender, incarnation and sequence number, so:
//   key   = HKDF-SHA256(run key, no salt, info "rl-gmac-v2" | channel)   (OpenSSL's EVP_KDF)
//   nonce = header.seq (8 bytes, big-endian) | header.incarnation (8) | header.sender,
//           zero-padded to kMaxSenderBytes                              (80 bytes)
// A Bus numbers each channel's messages 0, 1, 2, ... within one incarnation (its start time in
// microseconds, unique in a process), so a nonce repeats under one key only if two processes with
// the same sender name start within the same microsecond, which the launch script's names rule
// out. GCM hashes a nonce of other than 12 bytes into its first counter block (NIST SP 800-38D,
// GHASH): two distinct 80-byte nonces meet there with probability at most 6 / 2^128.
//
// Keys are per channel, not per sender, so that no message a forger can make costs a key
// derivation: the channels are those this process subscribes or publishes to (LCM hands it no
// others), each derived once and kept with its own cipher context; a sender name, which a forger
// chooses freely, only changes the nonce. So a forged message costs one GMAC pass over its bytes,
// what checking a real one of its size costs. A replayed message carries its original nonce and
// MAC: it verifies, and it is the Bus's freshness checks that drop it.
#pragma once

#include <cstddef>
#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <string_view>

struct evp_cipher_ctx_st;
struct evp_cipher_st;
struct evp_kdf_ctx_st;

namespace rl {

inline constexpr size_t kKeyBytes = 32;
inline constexpr size_t kMacBytes = 16;
// Longest sender name a message may carry (bytes): it is part of the MAC's nonce.
inline constexpr size_t kMaxSenderBytes = 64;

/// Reads a run's key file: a regular file of exactly kKeyBytes bytes that only its owner may read
/// or write (mode 0600 or 0400). Throws std::runtime_error naming the file and what is wrong.
std::string ReadKeyFile(const std::string& path);

/// Where header.mac starts in an encoded message whose first field is header_t (8-byte
/// fingerprint, run_id, sender, seq, utime, incarnation, mac) with a sender of `sender_length`
/// bytes.
constexpr size_t MacOffset(size_t sender_length) { return 8 + 8 + 4 + sender_length + 1 + 24; }

/// Whether `sender` may name a sender: 1 to kMaxSenderBytes printable ASCII characters, no space.
bool ValidSenderName(std::string_view sender);

/// The header of an encoded message, read from its raw bytes (MacOffset()'s layout).
struct WireHeader {
  int64_t fingerprint = 0;
  int64_t run_id = 0;
  std::string_view sender;  // points into the message's bytes
  int64_t seq = 0;
  int64_t utime = 0;
  int64_t incarnation = 0;
  size_t mac_offset = 0;
};

/// Reads the header of the `size` bytes at `data` into *out, checking every length against the
/// buffer. nullptr, or why the bytes cannot hold a message of ours: "too short for a header", or
/// "a sender name that is empty, longer than 64 bytes or not printable". O(sender length); no
/// allocation.
const char* ReadWireHeader(const uint8_t* data, size_t size, WireHeader* out);

/// Signs and verifies encoded messages with one run key. Reads the sender, sequence number and
/// incarnation from the header bytes before `mac_offset` (as MacOffset() lays them out). O(size)
/// per call; a key derivation (HKDF) only at a channel's first message; no allocation after it;
/// at most kMaxChannels keys kept, past which a channel's key is derived per message. Not
/// thread-safe (one per Bus).
class MessageAuthenticator {
 public:
  static constexpr size_t kMaxChannels = 64;

  // Throws std::invalid_argument when the key is not kKeyBytes long, std::runtime_error when
  // OpenSSL cannot provide AES-256-GCM or HKDF.
  explicit MessageAuthenticator(const std::string& key);
  MessageAuthenticator(const MessageAuthenticator&) = delete;
  MessageAuthenticator& operator=(const MessageAuthenticator&) = delete;
  ~MessageAuthenticator();

  /// Writes the MAC of data[0, size), published on `channel`, into data[mac_offset, mac_offset +
  /// kMacBytes), which must be zero. Returns false (and leaves data as it was) when the header
  /// has no room for a MAC, its sender name is not ValidSenderName(), or OpenSSL fails. The
  /// caller must never sign two different messages with one (channel, sender, incarnation, seq):
  /// that would reveal the channel's hash key.
  bool Sign(std::string_view channel, uint8_t* data, size_t size, size_t mac_offset);

  /// nullptr when the MAC at mac_offset is right for `channel`, else "no MAC" (all zero), "wrong
  /// MAC", "no room for a MAC" or "a sender name unfit for a nonce". Compares in constant time.
  const char* Verify(std::string_view channel, const uint8_t* data, size_t size, size_t mac_offset);

 private:
  struct CipherFree {
    void operator()(evp_cipher_ctx_st* c) const;
  };
  using Cipher = std::unique_ptr<evp_cipher_ctx_st, CipherFree>;

  // The cipher context keyed for `channel`: a kept one, or one made into scratch_. nullptr when
  // OpenSSL fails.
  evp_cipher_ctx_st* KeyFor(std::string_view channel);
  // A new cipher context keyed for `channel` (HKDF, then AES-256-GCM with our nonce length).
  Cipher Derive(std::string_view channel);
  // The tag of the message under `cipher`, with the MAC's bytes as zero.
  static bool Compute(evp_cipher_ctx_st* cipher, const uint8_t* data, size_t size,
                      size_t mac_offset, uint8_t* mac);

  std::string key_;
  std::unique_ptr<evp_cipher_st, void (*)(evp_cipher_st*)> gcm_;
  std::unique_ptr<evp_kdf_ctx_st, void (*)(evp_kdf_ctx_st*)> hkdf_;
  std::map<std::string, Cipher, std::less<>> channels_;
  Cipher scratch_;  // past kMaxChannels
};

}  // namespace rl
