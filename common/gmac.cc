#include "common/gmac.h"

#include <openssl/crypto.h>
#include <openssl/evp.h>

#include <algorithm>
#include <cstring>
#include <stdexcept>

#if defined(__AVX512F__) && defined(__AVX512BW__) && defined(__AVX512DQ__) && \
    defined(__VPCLMULQDQ__) && defined(__PCLMUL__)
#define RL_GMAC_KERNEL 1
#include <immintrin.h>
#else
#define RL_GMAC_KERNEL 0
#endif

namespace rl {

#if RL_GMAC_KERNEL
namespace {

// The kernel's representation of a field element: its 16 bytes reversed, read as a little-endian
// 128-bit integer. GCM numbers a block's bits from the first byte's most significant bit, bit i
// being the coefficient of x^i, so here the coefficient of x^i sits at integer bit 127 - i.
// Then a carry-less product of two elements holds the coefficient of x^k at bit 254 - k, and
// shifted left by one bit, its high 128 bits are the product's terms of degree below 128 and its
// low 128 bits those of degree 128 to 255 (both in this representation).
inline __m128i Reverse(__m128i x) {
  return _mm_shuffle_epi8(x, _mm_set_epi8(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15));
}

// 128-bit logical right shift by n (0 < n < 64): multiplies by x^n, dropping degrees past 127.
inline __m128i ShiftRight(__m128i a, int n) {
  return _mm_or_si128(_mm_srli_epi64(a, n), _mm_slli_epi64(_mm_srli_si128(a, 8), 64 - n));
}

// The element for the carry-less product hi:lo (256 bits, not yet shifted), reduced modulo
// g = x^128 + x^7 + x^2 + x + 1.
inline __m128i Reduce(__m128i lo, __m128i hi) {
  // Shift the 256-bit product left by one bit.
  const __m128i lo_carry = _mm_srli_epi64(lo, 63);
  const __m128i hi_carry = _mm_srli_epi64(hi, 63);
  lo = _mm_slli_epi64(lo, 1);
  hi = _mm_slli_epi64(hi, 1);
  hi = _mm_or_si128(hi, _mm_slli_si128(hi_carry, 8));
  hi = _mm_or_si128(hi, _mm_srli_si128(lo_carry, 8));
  lo = _mm_or_si128(lo, _mm_slli_si128(lo_carry, 8));
  // lo is c_high, the terms of degree 128 + j. Since x^128 = 1 + x + x^2 + x^7 (mod g),
  // c_high * x^128 = c_high * (1 + x + x^2 + x^7), whose shifts drop degrees 128 to 134: the
  // low 7 bits of lo, which fold back the same way from the top (<< 63, << 62, << 57 of its
  // low word).
  const __m128i low_word = _mm_slli_si128(lo, 8);
  const __m128i v = _mm_xor_si128(
      lo, _mm_xor_si128(_mm_xor_si128(_mm_slli_epi64(low_word, 63), _mm_slli_epi64(low_word, 62)),
                        _mm_slli_epi64(low_word, 57)));
  const __m128i folded = _mm_xor_si128(_mm_xor_si128(v, ShiftRight(v, 1)),
                                       _mm_xor_si128(ShiftRight(v, 2), ShiftRight(v, 7)));
  return _mm_xor_si128(hi, folded);
}

// a * b (mod g).
inline __m128i Multiply(__m128i a, __m128i b) {
  const __m128i lo = _mm_clmulepi64_si128(a, b, 0x00);
  const __m128i hi = _mm_clmulepi64_si128(a, b, 0x11);
  const __m128i mid =
      _mm_xor_si128(_mm_clmulepi64_si128(a, b, 0x01), _mm_clmulepi64_si128(a, b, 0x10));
  return Reduce(_mm_xor_si128(lo, _mm_slli_si128(mid, 8)),
                _mm_xor_si128(hi, _mm_srli_si128(mid, 8)));
}

// The XOR of a 512-bit register's four 128-bit lanes.
inline __m128i FoldLanes(__m512i v) {
  return _mm_xor_si128(
      _mm_xor_si128(_mm512_extracti64x2_epi64(v, 0), _mm512_extracti64x2_epi64(v, 1)),
      _mm_xor_si128(_mm512_extracti64x2_epi64(v, 2), _mm512_extracti64x2_epi64(v, 3)));
}

// The XOR of each 128-bit lane's two 64-bit halves, in the lane's low half (Karatsuba's middle
// factor; the high half is not used).
inline __m512i HalvesXor(__m512i v) { return _mm512_xor_si512(v, _mm512_bsrli_epi128(v, 8)); }

// Adds the unreduced lane-wise products data * keys to lo, hi and (Karatsuba) mid = (d0 ^ d1) *
// (k0 ^ k1), from which the cross terms are mid ^ lo ^ hi; keys_xor is HalvesXor(keys).
inline void MultiplyAdd(__m512i data, __m512i keys, __m512i keys_xor, __m512i* lo, __m512i* mid,
                        __m512i* hi) {
  *lo = _mm512_xor_si512(*lo, _mm512_clmulepi64_epi128(data, keys, 0x00));
  *hi = _mm512_xor_si512(*hi, _mm512_clmulepi64_epi128(data, keys, 0x11));
  *mid = _mm512_xor_si512(*mid, _mm512_clmulepi64_epi128(HalvesXor(data), keys_xor, 0x00));
}

inline __m128i ReduceLanes(__m512i lo, __m512i mid, __m512i hi) {
  const __m128i l = FoldLanes(lo);
  const __m128i h = FoldLanes(hi);
  const __m128i m = _mm_xor_si128(FoldLanes(mid), _mm_xor_si128(l, h));
  return Reduce(_mm_xor_si128(l, _mm_slli_si128(m, 8)), _mm_xor_si128(h, _mm_srli_si128(m, 8)));
}

// Rows of powers_: row r holds H^(64-4r), H^(63-4r), H^(62-4r), H^(61-4r) in lanes 0..3.
constexpr int kRows = Gmac::kPowerRows;
constexpr size_t kStride = 64 * kRows;  // bytes hashed per reduction

// GHASH (Horner's rule, X = (X ^ block) * H) over whole blocks from state x, a stride at a time:
// X * H^64 ^ B1 * H^64 ^ B2 * H^63 ^ ... ^ B64 * H, one reduction per stride. The powers and their
// Karatsuba halves are read from memory as they are used, so that the kernel keeps few registers
// live: zmm0-15 only, whose upper bits the compiler's vzeroupper clears at return (once a thread
// has touched zmm16-31, its context switches save and restore them).
__m128i HashBlocks(const uint8_t* powers, const uint8_t* powers_xor, __m128i x, const uint8_t* p,
                   size_t n) {
  if (n >= 64) {
    alignas(64) static constexpr uint8_t kReverse[64] = {
        15, 14, 13, 12, 11, 10, 9, 8, 7, 6, 5, 4, 3, 2, 1, 0,  //
        15, 14, 13, 12, 11, 10, 9, 8, 7, 6, 5, 4, 3, 2, 1, 0,  //
        15, 14, 13, 12, 11, 10, 9, 8, 7, 6, 5, 4, 3, 2, 1, 0,  //
        15, 14, 13, 12, 11, 10, 9, 8, 7, 6, 5, 4, 3, 2, 1, 0};
    const __m512i reverse = _mm512_load_si512(kReverse);
    auto row = [](const uint8_t* table, int r) { return _mm512_load_si512(table + 64 * r); };
    for (; n >= kStride; p += kStride, n -= kStride) {
      // Empty asm statements as barriers: the first keeps the compiler from hoisting the 32
      // loads of powers out of the loop (and spilling them), the second from computing all 48
      // products before adding them up (and spilling those).
      asm("" : "+r"(powers), "+r"(powers_xor));
      __m512i lo = _mm512_setzero_si512(), mid = lo, hi = lo;
      for (int r = 0; r < kRows; ++r) {
        __m512i data = _mm512_shuffle_epi8(_mm512_loadu_si512(p + 64 * r), reverse);
        if (r == 0) data = _mm512_xor_si512(data, _mm512_zextsi128_si512(x));
        MultiplyAdd(data, row(powers, r), row(powers_xor, r), &lo, &mid, &hi);
        asm("" : "+v"(lo), "+v"(mid), "+v"(hi));
      }
      x = ReduceLanes(lo, mid, hi);
    }
    for (; n >= 64; p += 64, n -= 64) {  // four blocks against H^4 .. H^1 (the last row)
      __m512i lo = _mm512_setzero_si512(), mid = lo, hi = lo;
      const __m512i data = _mm512_xor_si512(_mm512_shuffle_epi8(_mm512_loadu_si512(p), reverse),
                                            _mm512_zextsi128_si512(x));
      MultiplyAdd(data, row(powers, kRows - 1), row(powers_xor, kRows - 1), &lo, &mid, &hi);
      x = ReduceLanes(lo, mid, hi);
    }
  }
  // The last blocks (and the header's, the tail's and the length block) one at a time, against H.
  const __m128i h = _mm_load_si128(reinterpret_cast<const __m128i*>(powers + 64 * kRows - 16));
  for (; n >= 16; p += 16, n -= 16) {
    x = Multiply(_mm_xor_si128(x, Reverse(_mm_loadu_si128(reinterpret_cast<const __m128i*>(p)))),
                 h);
  }
  return x;
}

}  // namespace

bool Gmac::Accelerated() { return true; }

void Gmac::Blocks(const uint8_t* data, size_t size) {
  const __m128i x = _mm_load_si128(reinterpret_cast<const __m128i*>(state_));
  _mm_store_si128(reinterpret_cast<__m128i*>(state_),
                  HashBlocks(powers_, powers_xor_, x, data, size));
}

#else

bool Gmac::Accelerated() { return false; }
void Gmac::Blocks(const uint8_t*, size_t) {}

#endif  // RL_GMAC_KERNEL

void Gmac::CipherFree::operator()(evp_cipher_ctx_st* c) const { EVP_CIPHER_CTX_free(c); }

Gmac::Gmac() : cipher_(EVP_CIPHER_CTX_new()) {
  const EVP_CIPHER* aes = Accelerated() ? EVP_aes_256_ecb() : EVP_aes_256_gcm();
  if (cipher_ == nullptr ||
      EVP_EncryptInit_ex(cipher_.get(), aes, nullptr, nullptr, nullptr) != 1 ||
      EVP_CIPHER_CTX_set_padding(cipher_.get(), 0) != 1) {
    throw std::runtime_error(Accelerated() ? "OpenSSL provides no AES-256-ECB"
                                           : "OpenSSL provides no AES-256-GCM");
  }
}

Gmac::~Gmac() {
  OPENSSL_cleanse(powers_, sizeof(powers_));
  OPENSSL_cleanse(powers_xor_, sizeof(powers_xor_));
  OPENSSL_cleanse(mask_, sizeof(mask_));
}

bool Gmac::SetKey(const uint8_t* key) {
  has_key_ = ok_ = false;
  if (EVP_EncryptInit_ex(cipher_.get(), nullptr, nullptr, key, nullptr) != 1) return false;
#if RL_GMAC_KERNEL
  const uint8_t zero[16] = {};
  uint8_t h_bytes[16];
  int n = 0;
  if (EVP_EncryptUpdate(cipher_.get(), h_bytes, &n, zero, sizeof(zero)) != 1 || n != 16) {
    return false;
  }
  __m128i power[4 * kRows];  // power[i] = H^(i+1)
  power[0] = Reverse(_mm_loadu_si128(reinterpret_cast<const __m128i*>(h_bytes)));
  for (int i = 1; i < 4 * kRows; ++i) power[i] = Multiply(power[i - 1], power[0]);
  for (int r = 0; r < kRows; ++r) {
    for (int lane = 0; lane < 4; ++lane) {
      _mm_store_si128(reinterpret_cast<__m128i*>(powers_ + 64 * r + 16 * lane),
                      power[4 * kRows - 1 - 4 * r - lane]);
    }
    _mm512_store_si512(powers_xor_ + 64 * r, HalvesXor(_mm512_load_si512(powers_ + 64 * r)));
  }
  OPENSSL_cleanse(h_bytes, sizeof(h_bytes));
  OPENSSL_cleanse(power, sizeof(power));
#endif
  has_key_ = true;
  return true;
}

bool Gmac::Start(const uint8_t* nonce) {
  if (!Accelerated()) {
    ok_ = has_key_ && EVP_EncryptInit_ex(cipher_.get(), nullptr, nullptr, nullptr, nonce) == 1;
    return ok_;
  }
  // J0 = nonce | 0x00000001 (a 96-bit nonce); the tag mask is E_K(J0).
  uint8_t j0[16] = {};
  std::memcpy(j0, nonce, kNonceBytes);
  j0[15] = 1;
  int n = 0;
  ok_ = has_key_ && EVP_EncryptUpdate(cipher_.get(), mask_, &n, j0, sizeof(j0)) == 1 && n == 16;
  std::memset(state_, 0, sizeof(state_));
  partial_size_ = 0;
  total_ = 0;
  return ok_;
}

void Gmac::Update(const uint8_t* data, size_t size) {
  if (size == 0) return;
  if (!Accelerated()) {
    int n = 0;
    ok_ = ok_ && EVP_EncryptUpdate(cipher_.get(), nullptr, &n, data, static_cast<int>(size)) == 1;
    return;
  }
  total_ += size;
  if (partial_size_ > 0) {
    const size_t take = std::min(size, sizeof(partial_) - partial_size_);
    std::memcpy(partial_ + partial_size_, data, take);
    partial_size_ += take;
    data += take;
    size -= take;
    if (partial_size_ < sizeof(partial_)) return;
    Blocks(partial_, sizeof(partial_));
    partial_size_ = 0;
  }
  const size_t whole = size & ~size_t{15};
  Blocks(data, whole);
  std::memcpy(partial_, data + whole, size - whole);
  partial_size_ = size - whole;
}

bool Gmac::Finish(uint8_t* tag) {
  if (!Accelerated()) {
    uint8_t none[16];
    int n = 0;
    return ok_ && EVP_EncryptFinal_ex(cipher_.get(), none, &n) == 1 &&
           EVP_CIPHER_CTX_ctrl(cipher_.get(), EVP_CTRL_GCM_GET_TAG, kTagBytes, tag) == 1;
  }
  if (!ok_) return false;
  if (partial_size_ > 0) {  // the last block, zero-padded
    std::memset(partial_ + partial_size_, 0, sizeof(partial_) - partial_size_);
    Blocks(partial_, sizeof(partial_));
    partial_size_ = 0;
  }
  // The length block: the associated data's length in bits, then the ciphertext's (none), each
  // 64-bit big-endian.
  uint8_t lengths[16] = {};
  const uint64_t bits = total_ * 8;
  for (int i = 0; i < 8; ++i) lengths[7 - i] = static_cast<uint8_t>(bits >> (8 * i));
  Blocks(lengths, sizeof(lengths));
  // The hash back in GCM's byte order (the kernel's representation reversed), masked.
  for (size_t i = 0; i < kTagBytes; ++i) tag[i] = state_[15 - i] ^ mask_[i];
  return true;
}

}  // namespace rl
