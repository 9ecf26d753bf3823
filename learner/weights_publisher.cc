#include "learner/weights_publisher.h"

#include <algorithm>

#include "common/channels.h"
#include "common/crc32.h"

namespace rl::learner {

std::vector<rlmsg::weights_chunk_t> MakeWeightChunks(int64_t version,
                                                     const std::string& architecture,
                                                     const std::vector<float>& params,
                                                     int max_chunk_floats) {
  const int total = static_cast<int>(params.size());
  const int num_chunks = std::max(1, (total + max_chunk_floats - 1) / max_chunk_floats);
  const auto crc = static_cast<int64_t>(Crc32(params.data(), params.size() * sizeof(float)));
  std::vector<rlmsg::weights_chunk_t> chunks(static_cast<size_t>(num_chunks));
  for (int i = 0; i < num_chunks; ++i) {
    rlmsg::weights_chunk_t& c = chunks[static_cast<size_t>(i)];
    c.version = version;
    c.architecture = architecture;
    c.total_size = total;
    c.chunk_index = i;
    c.num_chunks = num_chunks;
    c.offset = i * max_chunk_floats;
    c.count = std::min(max_chunk_floats, total - c.offset);
    c.data.assign(params.begin() + c.offset, params.begin() + c.offset + c.count);
    c.crc32 = crc;
  }
  return chunks;
}

void WeightsPublisher::Start(int64_t version, const std::string& architecture,
                             const std::vector<float>& params) {
  chunks_ = MakeWeightChunks(version, architecture, params);
  next_ = 0;
}

void WeightsPublisher::Tick() {
  for (int i = 0; i < chunks_per_tick_ && next_ < chunks_.size(); ++i, ++next_) {
    bus_->Publish(channels::kWeights, &chunks_[next_], Port::kBulk);
  }
  if (!chunks_.empty() && next_ == chunks_.size() && published_version_ != chunks_[0].version) {
    published_version_ = chunks_[0].version;
  }
}

}  // namespace rl::learner
