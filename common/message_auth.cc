#include "common/message_auth.h"

#include <fcntl.h>
#include <openssl/core_names.h>
#include <openssl/crypto.h>
#include <openssl/evp.h>
#include <openssl/kdf.h>
#include <openssl/params.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <utility>

namespace rl {

std::string ReadKeyFile(const std::string& path) {
  auto fail = [&](const std::string& why) {
    throw std::runtime_error("key file '" + path + "': " + why);
  };
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) fail(std::strerror(errno));
  struct stat st {};
  std::string key(kKeyBytes + 1, '\0');
  ssize_t n = -1;
  int read_errno = 0;
  if (::fstat(fd, &st) != 0) {
    read_errno = errno;
  } else if (S_ISREG(st.st_mode)) {
    n = ::read(fd, key.data(), key.size());
    read_errno = errno;
  }
  ::close(fd);
  if (read_errno != 0 && n < 0) fail(std::strerror(read_errno));
  if (!S_ISREG(st.st_mode)) fail("not a regular file");
  if ((st.st_mode & 077) != 0) {
    fail(
        "readable or writable by others than its owner (chmod 600 it; the key lets anyone who "
        "reads it publish into the run)");
  }
  if (static_cast<size_t>(n) != kKeyBytes) {
    fail("holds " + std::to_string(n) + (n > static_cast<ssize_t>(kKeyBytes) ? "+" : "") +
         " bytes, not " + std::to_string(kKeyBytes));
  }
  key.resize(kKeyBytes);
  return key;
}

namespace {

constexpr char kLabel[] = "rl-gmac-v2";
// The nonce: seq, incarnation, the sender zero-padded (message_auth.h).
constexpr size_t kNonceBytes = 8 + 8 + kMaxSenderBytes;

int64_t ReadBigEndian(const uint8_t* p, int bytes) {
  uint64_t v = 0;
  for (int i = 0; i < bytes; ++i) v = (v << 8) | p[i];
  const int shift = 64 - 8 * bytes;  // sign-extend
  return static_cast<int64_t>(v << shift) >> shift;
}

// The header fields before the MAC (MacOffset()): sender at 20, then seq, utime, incarnation.
size_t SenderLength(size_t mac_offset) { return mac_offset - MacOffset(0); }
const uint8_t* Sender(const uint8_t* data) { return data + 20; }

bool HasRoom(size_t size, size_t mac_offset) {
  return mac_offset >= MacOffset(0) && mac_offset <= size && size - mac_offset >= kMacBytes &&
         size <= static_cast<size_t>(std::numeric_limits<int>::max());
}

std::string_view SenderOf(const uint8_t* data, size_t mac_offset) {
  return {reinterpret_cast<const char*>(Sender(data)), SenderLength(mac_offset)};
}

}  // namespace

bool ValidSenderName(std::string_view sender) {
  if (sender.empty() || sender.size() > kMaxSenderBytes) return false;
  for (const char c : sender) {
    if (c < '!' || c > '~') return false;
  }
  return true;
}

const char* ReadWireHeader(const uint8_t* data, size_t size, WireHeader* out) {
  if (size < MacOffset(0) + kMacBytes) return "too short for a header";
  // The sender: an int32 length counting its NUL, the bytes, the NUL.
  const int64_t length = ReadBigEndian(data + 16, 4);
  if (length < 2 || length > static_cast<int64_t>(kMaxSenderBytes) + 1) {
    return "a sender name that is empty, longer than 64 bytes or not printable";
  }
  const size_t sender = static_cast<size_t>(length) - 1;
  out->mac_offset = MacOffset(sender);
  if (size < out->mac_offset + kMacBytes) return "too short for a header";
  out->sender = SenderOf(data, out->mac_offset);
  if (data[20 + sender] != 0 || !ValidSenderName(out->sender)) {
    return "a sender name that is empty, longer than 64 bytes or not printable";
  }
  out->fingerprint = ReadBigEndian(data, 8);
  out->run_id = ReadBigEndian(data + 8, 8);
  out->seq = ReadBigEndian(data + out->mac_offset - 24, 8);
  out->utime = ReadBigEndian(data + out->mac_offset - 16, 8);
  out->incarnation = ReadBigEndian(data + out->mac_offset - 8, 8);
  return nullptr;
}

void MessageAuthenticator::CipherFree::operator()(evp_cipher_ctx_st* c) const {
  EVP_CIPHER_CTX_free(c);
}

MessageAuthenticator::MessageAuthenticator(const std::string& key)
    : key_(key),
      gcm_(EVP_CIPHER_fetch(nullptr, "AES-256-GCM", nullptr), EVP_CIPHER_free),
      hkdf_(nullptr, EVP_KDF_CTX_free) {
  if (key_.size() != kKeyBytes) {
    throw std::invalid_argument("a message key has " + std::to_string(kKeyBytes) + " bytes, not " +
                                std::to_string(key_.size()));
  }
  EVP_KDF* kdf = EVP_KDF_fetch(nullptr, "HKDF", nullptr);
  if (kdf != nullptr) hkdf_.reset(EVP_KDF_CTX_new(kdf));
  EVP_KDF_free(kdf);  // the context holds its own reference
  if (gcm_ == nullptr || hkdf_ == nullptr) {
    throw std::runtime_error("OpenSSL provides no AES-256-GCM or no HKDF");
  }
  if (Derive("") == nullptr) throw std::runtime_error("OpenSSL cannot derive a message key");
}

MessageAuthenticator::~MessageAuthenticator() { OPENSSL_cleanse(key_.data(), key_.size()); }

MessageAuthenticator::Cipher MessageAuthenticator::Derive(std::string_view channel) {
  // info = label | channel: the label has a fixed length, so the channel is what follows it.
  char digest[] = "SHA256";
  std::string info(kLabel);
  info.append(channel);
  const OSSL_PARAM params[] = {
      OSSL_PARAM_construct_utf8_string(OSSL_KDF_PARAM_DIGEST, digest, 0),
      OSSL_PARAM_construct_octet_string(OSSL_KDF_PARAM_KEY, key_.data(), key_.size()),
      OSSL_PARAM_construct_octet_string(OSSL_KDF_PARAM_INFO, info.data(), info.size()),
      OSSL_PARAM_construct_end()};
  unsigned char channel_key[kKeyBytes];
  Cipher cipher(EVP_CIPHER_CTX_new());
  const bool ok = cipher != nullptr &&
                  EVP_KDF_derive(hkdf_.get(), channel_key, sizeof(channel_key), params) == 1 &&
                  EVP_EncryptInit_ex(cipher.get(), gcm_.get(), nullptr, nullptr, nullptr) == 1 &&
                  EVP_CIPHER_CTX_ctrl(cipher.get(), EVP_CTRL_GCM_SET_IVLEN,
                                      static_cast<int>(kNonceBytes), nullptr) == 1 &&
                  EVP_EncryptInit_ex(cipher.get(), nullptr, nullptr, channel_key, nullptr) == 1;
  OPENSSL_cleanse(channel_key, sizeof(channel_key));
  if (!ok) cipher.reset();
  return cipher;
}

evp_cipher_ctx_st* MessageAuthenticator::KeyFor(std::string_view channel) {
  if (const auto it = channels_.find(channel); it != channels_.end()) return it->second.get();
  Cipher cipher = Derive(channel);
  if (cipher == nullptr) return nullptr;
  if (channels_.size() < kMaxChannels) {
    return channels_.emplace(std::string(channel), std::move(cipher)).first->second.get();
  }
  scratch_ = std::move(cipher);
  return scratch_.get();
}

bool MessageAuthenticator::Compute(evp_cipher_ctx_st* cipher, const uint8_t* data, size_t size,
                                   size_t mac_offset, uint8_t* mac) {
  static constexpr uint8_t kZero[kMacBytes] = {};
  uint8_t nonce[kNonceBytes] = {};
  std::memcpy(nonce, data + mac_offset - 24, 8);     // seq
  std::memcpy(nonce + 8, data + mac_offset - 8, 8);  // incarnation
  std::memcpy(nonce + 16, Sender(data), SenderLength(mac_offset));
  // The whole message as associated data, with the MAC's bytes as zero; nothing encrypted.
  const size_t tail = mac_offset + kMacBytes;
  int out = 0;
  unsigned char none[16];
  return EVP_EncryptInit_ex(cipher, nullptr, nullptr, nullptr, nonce) == 1 &&
         EVP_EncryptUpdate(cipher, nullptr, &out, data, static_cast<int>(mac_offset)) == 1 &&
         EVP_EncryptUpdate(cipher, nullptr, &out, kZero, kMacBytes) == 1 &&
         (tail == size || EVP_EncryptUpdate(cipher, nullptr, &out, data + tail,
                                            static_cast<int>(size - tail)) == 1) &&
         EVP_EncryptFinal_ex(cipher, none, &out) == 1 &&
         EVP_CIPHER_CTX_ctrl(cipher, EVP_CTRL_GCM_GET_TAG, kMacBytes, mac) == 1;
}

bool MessageAuthenticator::Sign(std::string_view channel, uint8_t* data, size_t size,
                                size_t mac_offset) {
  if (!HasRoom(size, mac_offset) || !ValidSenderName(SenderOf(data, mac_offset))) return false;
  evp_cipher_ctx_st* cipher = KeyFor(channel);
  uint8_t mac[kMacBytes];
  if (cipher == nullptr || !Compute(cipher, data, size, mac_offset, mac)) return false;
  std::memcpy(data + mac_offset, mac, kMacBytes);
  return true;
}

const char* MessageAuthenticator::Verify(std::string_view channel, const uint8_t* data, size_t size,
                                         size_t mac_offset) {
  if (!HasRoom(size, mac_offset)) return "no room for a MAC";
  if (SenderLength(mac_offset) > kMaxSenderBytes) return "a sender name unfit for a nonce";
  const uint8_t* got = data + mac_offset;
  uint8_t any = 0;
  for (size_t i = 0; i < kMacBytes; ++i) any |= got[i];
  if (any == 0) return "no MAC";
  evp_cipher_ctx_st* cipher = KeyFor(channel);
  uint8_t want[kMacBytes];
  if (cipher == nullptr || !Compute(cipher, data, size, mac_offset, want) ||
      CRYPTO_memcmp(want, got, kMacBytes) != 0) {
    return "wrong MAC";
  }
  return nullptr;
}

}  // namespace rl
