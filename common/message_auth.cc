#include "common/message_auth.h"

#include <fcntl.h>
#include <openssl/core_names.h>
#include <openssl/crypto.h>
#include <openssl/evp.h>
#include <openssl/params.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <stdexcept>

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

MessageAuthenticator::MessageAuthenticator(const std::string& key) : key_(key) {
  if (key_.size() != kKeyBytes) {
    throw std::invalid_argument("a message key has " + std::to_string(kKeyBytes) + " bytes, not " +
                                std::to_string(key_.size()));
  }
  mac_ = EVP_MAC_fetch(nullptr, OSSL_MAC_NAME_HMAC, nullptr);
  if (mac_ != nullptr) ctx_ = EVP_MAC_CTX_new(mac_);
  if (ctx_ == nullptr) throw std::runtime_error("OpenSSL provides no HMAC");
  char digest[] = "SHA256";
  const OSSL_PARAM params[] = {OSSL_PARAM_construct_utf8_string(OSSL_MAC_PARAM_DIGEST, digest, 0),
                               OSSL_PARAM_construct_end()};
  if (EVP_MAC_CTX_set_params(ctx_, params) != 1) {
    throw std::runtime_error("OpenSSL provides no HMAC-SHA256");
  }
}

MessageAuthenticator::~MessageAuthenticator() {
  EVP_MAC_CTX_free(ctx_);
  EVP_MAC_free(mac_);
}

bool MessageAuthenticator::Compute(const uint8_t* data, size_t size, size_t mac_offset,
                                   uint8_t* mac) {
  static constexpr uint8_t kZero[kMacBytes] = {};
  uint8_t full[EVP_MAX_MD_SIZE];
  size_t full_size = 0;
  const size_t tail = mac_offset + kMacBytes;
  const auto* key = reinterpret_cast<const unsigned char*>(key_.data());
  if (EVP_MAC_init(ctx_, key, key_.size(), nullptr) != 1 ||
      EVP_MAC_update(ctx_, data, mac_offset) != 1 || EVP_MAC_update(ctx_, kZero, kMacBytes) != 1 ||
      EVP_MAC_update(ctx_, data + tail, size - tail) != 1 ||
      EVP_MAC_final(ctx_, full, &full_size, sizeof(full)) != 1 || full_size < kMacBytes) {
    return false;
  }
  std::memcpy(mac, full, kMacBytes);
  return true;
}

bool MessageAuthenticator::Sign(uint8_t* data, size_t size, size_t mac_offset) {
  if (mac_offset > size || size - mac_offset < kMacBytes) return false;
  uint8_t mac[kMacBytes];
  if (!Compute(data, size, mac_offset, mac)) return false;
  std::memcpy(data + mac_offset, mac, kMacBytes);
  return true;
}

const char* MessageAuthenticator::Verify(const uint8_t* data, size_t size, size_t mac_offset) {
  if (mac_offset > size || size - mac_offset < kMacBytes) return "no room for a MAC";
  const uint8_t* got = data + mac_offset;
  uint8_t any = 0;
  for (size_t i = 0; i < kMacBytes; ++i) any |= got[i];
  if (any == 0) return "no MAC";
  uint8_t want[kMacBytes];
  if (!Compute(data, size, mac_offset, want)) return "wrong MAC";
  return CRYPTO_memcmp(want, got, kMacBytes) == 0 ? nullptr : "wrong MAC";
}

}  // namespace rl
