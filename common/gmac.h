// AES-256-GMAC (NIST SP 800-38D: GCM with associated data only, nothing encrypted): the 16-byte
// tag of a message under a 32-byte key and a 12-byte nonce, bit for bit OpenSSL's AES-256-GCM tag
// over the message as associated data.
//
//   tag = E_K(nonce | 0x00000001) ^ GHASH_H(message, zero-padded to 16 bytes | length block)
//   H   = E_K(0^128)
//
// Builds for a CPU with AVX-512 (F, BW, DQ) and VPCLMULQDQ (-march=native on such a CPU) compute
// GHASH with our own kernel: four blocks per carry-less multiply, three multiplies per product
// (Karatsuba), one reduction per 64 blocks (1 KB) against the precomputed powers H^64 .. H^1 and
// their Karatsuba halves: about 4 times OpenSSL 3.0's AES-GCM on our pixel batches (bench_replay
// `mac_*` rows), bound by its three carry-less multiplies per 64 bytes. AES stays
// OpenSSL's (H once per key, the tag mask once per message). Every other build uses OpenSSL's
// AES-GCM whole (the portable path). The unit tests compare the kernel's tags with OpenSSL's
// over every length up to 2 KB, a pixel batch's and any split of a message into pieces.
//
// Contract: SetKey O(1) (64 field multiplications); Start O(1); Update O(size), any split of a
// message giving the same tag; Finish O(1). No allocation after construction. Carry-less
// multiplies and XORs only: no branch or memory access depends on the key or the data. Not
// thread-safe.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>

struct evp_cipher_ctx_st;

namespace rl {

class Gmac {
 public:
  static constexpr size_t kKeyBytes = 32;
  static constexpr size_t kNonceBytes = 12;
  static constexpr size_t kTagBytes = 16;
  static constexpr int kPowerRows = 16;  // the kernel's powers of H, four to a row

  // Whether this build hashes with the AVX-512 kernel (else OpenSSL's AES-GCM does it all).
  static bool Accelerated();

  // Throws std::runtime_error when OpenSSL provides no AES-256 (ECB or GCM).
  Gmac();
  Gmac(const Gmac&) = delete;
  Gmac& operator=(const Gmac&) = delete;
  ~Gmac();

  /// Sets the key (kKeyBytes). False when OpenSSL fails; the Gmac has no key then.
  bool SetKey(const uint8_t* key);
  /// Starts a message under `nonce` (kNonceBytes). Needs a key. False when OpenSSL fails.
  bool Start(const uint8_t* nonce);
  /// Hashes the message's next `size` bytes (size <= INT_MAX).
  void Update(const uint8_t* data, size_t size);
  /// Writes the message's tag (kTagBytes). False when OpenSSL failed anywhere since Start().
  bool Finish(uint8_t* tag);

 private:
  struct CipherFree {
    void operator()(evp_cipher_ctx_st* c) const;
  };
  // Hashes whole blocks into state_ (the kernel).
  void Blocks(const uint8_t* data, size_t size);

  std::unique_ptr<evp_cipher_ctx_st, CipherFree> cipher_;  // AES-256-ECB (kernel) or -GCM
  bool has_key_ = false;
  bool ok_ = false;  // no OpenSSL failure since Start()
  // The kernel's state: H^64 .. H^1 in its representation (four to a 64-byte row, the highest
  // power first) and the XOR of each power's two halves (Karatsuba's middle factor), the hash so
  // far, the unhashed tail of a block, the message's length and the tag mask E_K(J0).
  alignas(64) uint8_t powers_[kPowerRows * 64] = {};
  alignas(64) uint8_t powers_xor_[kPowerRows * 64] = {};
  alignas(16) uint8_t state_[16] = {};
  uint8_t partial_[16] = {};
  size_t partial_size_ = 0;
  uint64_t total_ = 0;
  uint8_t mask_[16] = {};
};

}  // namespace rl
