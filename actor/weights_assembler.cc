#include "actor/weights_assembler.h"

#include <algorithm>
#include <utility>

#include "common/crc32.h"

namespace rl::actor {

WeightsAssembler::WeightsAssembler(SizeOf size_of) : size_of_(std::move(size_of)) {}

bool WeightsAssembler::Plausible(const rlmsg::weights_chunk_t& chunk) {
  if (sized_architecture_ != chunk.architecture) {
    sized_floats_ = size_of_(chunk.architecture);
    sized_architecture_ = chunk.architecture;
  }
  return sized_floats_ > 0 && chunk.total_size == sized_floats_ &&
         chunk.num_chunks <= chunk.total_size;
}

bool WeightsAssembler::Add(const rlmsg::weights_chunk_t& chunk) {
  if (chunk.version <= complete_version_) return false;
  if (partial_.count(chunk.version) == 0 && !Plausible(chunk)) {
    if (chunk.version != last_refused_version_) ++refused_;
    last_refused_version_ = chunk.version;
    return false;
  }
  auto [it, inserted] = partial_.try_emplace(chunk.version);
  Partial& p = it->second;
  if (inserted) {
    p.architecture = chunk.architecture;
    p.params.assign(static_cast<size_t>(chunk.total_size), 0.0f);
    p.have.assign(static_cast<size_t>(chunk.num_chunks), false);
    p.crc32 = chunk.crc32;
    // Keep at most two versions in assembly: drop the oldest.
    while (partial_.size() > 2) partial_.erase(partial_.begin());
    it = partial_.find(chunk.version);
    if (it == partial_.end()) return false;
  }
  Partial& q = it->second;
  const bool consistent = q.architecture == chunk.architecture &&
                          static_cast<int>(q.params.size()) == chunk.total_size &&
                          static_cast<int>(q.have.size()) == chunk.num_chunks &&
                          q.crc32 == chunk.crc32;
  if (!consistent) {
    ++rejected_;
    partial_.erase(it);
    return false;
  }
  const auto index = static_cast<size_t>(chunk.chunk_index);
  if (q.have[index]) return false;  // a duplicate
  std::copy(chunk.data.begin(), chunk.data.end(), q.params.begin() + chunk.offset);
  q.have[index] = true;
  if (++q.received < chunk.num_chunks) return false;

  // Complete: verify the checksum of the whole buffer.
  const uint32_t crc = Crc32(q.params.data(), q.params.size() * sizeof(float));
  if (static_cast<int64_t>(crc) != q.crc32) {
    ++rejected_;
    partial_.erase(it);
    return false;
  }
  Weights w;
  w.version = chunk.version;
  w.architecture = std::move(q.architecture);
  w.params = std::move(q.params);
  complete_version_ = chunk.version;
  ready_ = std::move(w);
  // Versions older than this one can never be used now.
  partial_.erase(partial_.begin(), partial_.upper_bound(complete_version_));
  return true;
}

std::optional<Weights> WeightsAssembler::Take() {
  std::optional<Weights> out = std::move(ready_);
  ready_.reset();
  return out;
}

}  // namespace rl::actor
