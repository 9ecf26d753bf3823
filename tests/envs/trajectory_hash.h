// FNV-1a over the bytes of the values added: a fingerprint of a trajectory, so that determinism
// tests compare whole episodes bit for bit.
#pragma once

#include <cstdint>
#include <cstring>

namespace rl::envs {

class TrajectoryHash {
 public:
  template <typename T>
  void Add(const T& value) {
    unsigned char bytes[sizeof(T)];
    std::memcpy(bytes, &value, sizeof(T));
    for (unsigned char b : bytes) hash_ = (hash_ ^ b) * 1099511628211ULL;
  }
  uint64_t value() const { return hash_; }

 private:
  uint64_t hash_ = 14695981039346656037ULL;
};

}  // namespace rl::envs
