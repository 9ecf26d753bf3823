#include "common/message_auth.h"

#include <fcntl.h>
#include <openssl/crypto.h>
#include <openssl/evp.h>
#include <openssl/hmac.h>
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

constexpr char kLabel[] = "rl-gmac-v1";

int64_t ReadBigEndian64(const uint8_t* p) {
  uint64_t v = 0;
  for (int i = 0; i < 8; ++i) v = (v << 8) | p[i];
  return static_cast<int64_t>(v);
}

// The header fields before the MAC (MacOffset()): sender at 20, then seq, utime, incarnation.
size_t SenderLength(size_t mac_offset) { return mac_offset - MacOffset(0); }
const uint8_t* Sender(const uint8_t* data) { return data + 20; }
const uint8_t* Seq(const uint8_t* data, size_t mac_offset) { return data + mac_offset - 24; }
const uint8_t* Incarnation(const uint8_t* data, size_t mac_offset) { return data + mac_offset - 8; }

bool HasRoom(size_t size, size_t mac_offset) {
  return mac_offset >= MacOffset(0) && mac_offset <= size && size - mac_offset >= kMacBytes &&
         size <= static_cast<size_t>(std::numeric_limits<int>::max());
}

// Appends a length-prefixed field, so that no two (channel, sender) pairs read alike.
void AppendField(std::string* out, const void* data, size_t size) {
  const uint32_t n = static_cast<uint32_t>(size);
  out->append(reinterpret_cast<const char*>(&n), sizeof(n));
  out->append(static_cast<const char*>(data), size);
}

}  // namespace

MessageAuthenticator::MessageAuthenticator(const std::string& key)
    : key_(key), scratch_(std::make_unique<Gmac>()) {
  if (key_.size() != kKeyBytes) {
    throw std::invalid_argument("a message key has " + std::to_string(kKeyBytes) + " bytes, not " +
                                std::to_string(key_.size()));
  }
  unsigned char probe[32];
  unsigned int probe_size = 0;
  if (HMAC(EVP_sha256(), key_.data(), static_cast<int>(key_.size()),
           reinterpret_cast<const unsigned char*>(kLabel), sizeof(kLabel), probe,
           &probe_size) == nullptr) {
    throw std::runtime_error("OpenSSL provides no HMAC-SHA256");
  }
}

MessageAuthenticator::~MessageAuthenticator() = default;

Gmac* MessageAuthenticator::KeyFor(std::string_view channel, const uint8_t* data, size_t mac_offset,
                                   bool* derived) {
  lookup_.assign(channel);
  lookup_.push_back('\0');
  lookup_.append(reinterpret_cast<const char*>(Sender(data)), SenderLength(mac_offset));
  const int64_t incarnation = ReadBigEndian64(Incarnation(data, mac_offset));
  *derived = false;
  if (auto it = streams_.find(lookup_);
      it != streams_.end() && it->second.incarnation == incarnation) {
    return it->second.gmac.get();
  }
  // HMAC-SHA256(run key, label | channel | sender | incarnation), each field length-prefixed.
  std::string info;
  AppendField(&info, kLabel, sizeof(kLabel) - 1);
  AppendField(&info, channel.data(), channel.size());
  AppendField(&info, Sender(data), SenderLength(mac_offset));
  AppendField(&info, Incarnation(data, mac_offset), 8);
  unsigned char stream_key[32];
  unsigned int stream_key_size = 0;
  if (HMAC(EVP_sha256(), key_.data(), static_cast<int>(key_.size()),
           reinterpret_cast<const unsigned char*>(info.data()), info.size(), stream_key,
           &stream_key_size) == nullptr ||
      stream_key_size != sizeof(stream_key) || !scratch_->SetKey(stream_key)) {
    OPENSSL_cleanse(stream_key, sizeof(stream_key));
    return nullptr;
  }
  OPENSSL_cleanse(stream_key, sizeof(stream_key));
  *derived = true;
  return scratch_.get();
}

void MessageAuthenticator::Keep(const uint8_t* data, size_t mac_offset) {
  const int64_t incarnation = ReadBigEndian64(Incarnation(data, mac_offset));
  auto it = streams_.find(lookup_);
  if (it == streams_.end()) {
    if (streams_.size() >= kMaxStreams) return;
    it = streams_.emplace(lookup_, Stream{}).first;
  } else if (incarnation < it->second.incarnation) {
    return;  // an older incarnation (a replayed message, about to be dropped): keep the newer
  }
  it->second.incarnation = incarnation;
  std::swap(it->second.gmac, scratch_);
  if (scratch_ == nullptr) scratch_ = std::make_unique<Gmac>();
}

bool MessageAuthenticator::Compute(Gmac* gmac, const uint8_t* data, size_t size, size_t mac_offset,
                                   uint8_t* mac) {
  static constexpr uint8_t kZero[kMacBytes] = {};
  uint8_t nonce[Gmac::kNonceBytes] = {};
  std::memcpy(nonce, Seq(data, mac_offset), 8);
  // The whole message with the MAC's bytes as zero.
  if (!gmac->Start(nonce)) return false;
  gmac->Update(data, mac_offset);
  gmac->Update(kZero, kMacBytes);
  const size_t tail = mac_offset + kMacBytes;
  gmac->Update(data + tail, size - tail);
  return gmac->Finish(mac);
}

bool MessageAuthenticator::Sign(std::string_view channel, uint8_t* data, size_t size,
                                size_t mac_offset) {
  if (!HasRoom(size, mac_offset)) return false;
  bool derived = false;
  Gmac* gmac = KeyFor(channel, data, mac_offset, &derived);
  uint8_t mac[kMacBytes];
  if (gmac == nullptr || !Compute(gmac, data, size, mac_offset, mac)) return false;
  if (derived) Keep(data, mac_offset);
  std::memcpy(data + mac_offset, mac, kMacBytes);
  return true;
}

const char* MessageAuthenticator::Verify(std::string_view channel, const uint8_t* data, size_t size,
                                         size_t mac_offset) {
  if (!HasRoom(size, mac_offset)) return "no room for a MAC";
  const uint8_t* got = data + mac_offset;
  uint8_t any = 0;
  for (size_t i = 0; i < kMacBytes; ++i) any |= got[i];
  if (any == 0) return "no MAC";
  bool derived = false;
  Gmac* gmac = KeyFor(channel, data, mac_offset, &derived);
  uint8_t want[kMacBytes];
  if (gmac == nullptr || !Compute(gmac, data, size, mac_offset, want) ||
      CRYPTO_memcmp(want, got, kMacBytes) != 0) {
    return "wrong MAC";
  }
  if (derived) Keep(data, mac_offset);
  return nullptr;
}

}  // namespace rl
