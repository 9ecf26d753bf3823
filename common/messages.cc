#include "common/messages.h"

#include <cmath>
#include <cstring>
#include <vector>

namespace rl {
namespace {

bool AllFinite(const std::vector<float>& v) {
  for (float x : v) {
    if (!std::isfinite(x)) return false;
  }
  return true;
}

bool HeaderOk(const rlmsg::header_t& h) { return !h.sender.empty() && h.seq >= 0; }

// Frame geometry of pixel messages: positive and small enough that products cannot overflow.
bool GeometryOk(int32_t height, int32_t width, int32_t stack) {
  return height > 0 && width > 0 && stack > 0 && height <= 4096 && width <= 4096 && stack <= 64;
}

// The per-transition columns both transition and sample messages carry: count transitions,
// action_width floats each (finite), discounts in [0, 1], and every other float finite.
const char* CheckColumns(int32_t count, int32_t action_width, int32_t num_action_values,
                         const std::vector<float>& action, const std::vector<float>& reward,
                         const std::vector<float>& discount) {
  if (action_width < 1 || action_width > kMaxActionWidth) return "action_width outside [1, 64]";
  if (int64_t{count} * action_width != num_action_values) return "num_action_values mismatch";
  if (!AllFinite(action)) return "non-finite action";
  if (!AllFinite(reward) || !AllFinite(discount)) return "non-finite value";
  for (float d : discount) {
    if (d < 0.0f || d > 1.0f) return "discount outside [0, 1]";
  }
  return nullptr;
}

// Flat or pixel observations of `count` transitions, exactly one kind; `has_pixels` says whether
// any pixel array is non-empty.
const char* CheckObservationKind(int32_t count, int32_t obs_size, int32_t num_values,
                                 int32_t height, int32_t width, int32_t stack, bool has_pixels) {
  const bool flat = obs_size > 0;
  const bool pixels = stack > 0 || height > 0 || width > 0;
  if (flat == pixels) return "neither or both of flat and pixel observations";
  if (flat) {
    if (int64_t{obs_size} * count != num_values) return "num_values mismatch";
    if (has_pixels) return "pixel arrays in a flat batch";
    return nullptr;
  }
  if (!GeometryOk(height, width, stack)) return "bad frame geometry";
  if (num_values != 0) return "flat observations in a pixel batch";
  return nullptr;
}

}  // namespace

const char* Validate(const rlmsg::transition_batch_t& m) {
  if (!HeaderOk(m.header)) return "bad header";
  if (m.actor_id < 0) return "negative actor_id";
  if (m.count < 0) return "negative count";
  if (const char* why = CheckObservationKind(m.count, m.obs_size, m.num_values, m.height, m.width,
                                             m.stack, m.num_frames != 0 || m.num_refs != 0)) {
    return why;
  }
  if (m.obs_size > 0) {
    if (m.count == 0) return "empty batch";
    if (!AllFinite(m.obs) || !AllFinite(m.next_obs)) return "non-finite value";
  } else {
    if (m.num_frames < 0 || m.num_frames + m.count == 0) return "empty batch";
    if (int64_t{m.num_frames} * m.height * m.width != m.num_bytes) return "num_bytes mismatch";
    if (int64_t{m.count} * m.stack != m.num_refs) return "num_refs mismatch";
    for (size_t i = 1; i < m.frame_id.size(); ++i) {
      if (m.frame_id[i] <= m.frame_id[i - 1]) return "frame ids not increasing";
    }
    if (!m.frame_id.empty() && m.frame_id.front() < 0) return "negative frame id";
  }
  if (const char* why = CheckColumns(m.count, m.action_width, m.num_action_values, m.action,
                                     m.reward, m.discount)) {
    return why;
  }
  if (!AllFinite(m.priority)) return "non-finite value";
  for (float p : m.priority) {
    if (p < 0.0f) return "negative priority";
  }
  return nullptr;
}

const char* Validate(const rlmsg::sample_batch_t& m) {
  if (!HeaderOk(m.header)) return "bad header";
  if (m.count <= 0) return "empty batch";
  if (const char* why = CheckObservationKind(m.count, m.obs_size, m.num_values, m.height, m.width,
                                             m.stack, m.num_bytes != 0)) {
    return why;
  }
  if (m.obs_size > 0) {
    if (!AllFinite(m.obs) || !AllFinite(m.next_obs)) return "non-finite value";
  } else if (int64_t{m.count} * m.stack * m.height * m.width != m.num_bytes) {
    return "num_bytes mismatch";
  }
  if (const char* why = CheckColumns(m.count, m.action_width, m.num_action_values, m.action,
                                     m.reward, m.discount)) {
    return why;
  }
  if (!AllFinite(m.weight)) return "non-finite value";
  return nullptr;
}

const char* Validate(const rlmsg::priority_update_t& m) {
  if (!HeaderOk(m.header)) return "bad header";
  if (m.count <= 0) return "empty update";
  for (size_t i = 0; i < m.priority.size(); ++i) {
    if (!std::isfinite(m.priority[i]) || m.priority[i] < 0.0f) return "bad priority";
    if (m.index[i] < 0) return "negative index";
  }
  return nullptr;
}

const char* Validate(const rlmsg::sample_request_t& m) {
  if (!HeaderOk(m.header)) return "bad header";
  if (m.batch_size <= 0 || m.batch_size > 65536) return "batch_size outside [1, 65536]";
  return nullptr;
}

const char* Validate(const rlmsg::weights_chunk_t& m) {
  if (!HeaderOk(m.header)) return "bad header";
  if (m.version < 0) return "negative version";
  if (m.architecture.empty()) return "empty architecture";
  if (m.total_size <= 0 || m.num_chunks <= 0) return "empty weights";
  if (m.chunk_index < 0 || m.chunk_index >= m.num_chunks) return "chunk_index out of range";
  if (m.offset < 0 || m.count <= 0 ||
      static_cast<int64_t>(m.offset) + m.count > static_cast<int64_t>(m.total_size)) {
    return "chunk outside the buffer";
  }
  if (m.crc32 < 0 || m.crc32 > 0xFFFFFFFFLL) return "crc32 out of range";
  if (!AllFinite(m.data)) return "non-finite value";
  return nullptr;
}

const char* Validate(const rlmsg::checkpoint_t& m) {
  if (!HeaderOk(m.header)) return "bad header";
  if (m.path.empty()) return "empty path";
  if (m.update < 0 || m.env_steps < 0 || !std::isfinite(m.wall_seconds)) return "bad counters";
  return nullptr;
}

const char* Validate(const rlmsg::flow_control_t& m) {
  if (!HeaderOk(m.header)) return "bad header";
  if (m.insert_allowed != 0 && m.insert_allowed != 1) return "insert_allowed not 0 or 1";
  if (!std::isfinite(m.samples_per_insert)) return "non-finite value";
  if (m.insert_credit < -1) return "insert_credit below -1";
  if (m.num_actors < 0 || static_cast<size_t>(m.num_actors) != m.actor_id.size() ||
      m.actor_inserts.size() != m.actor_id.size()) {
    return "num_actors mismatch";
  }
  for (int64_t n : m.actor_inserts) {
    if (n < 0) return "negative actor_inserts";
  }
  return nullptr;
}

const char* Validate(const rlmsg::eval_result_t& m) {
  if (!HeaderOk(m.header)) return "bad header";
  if (m.episodes <= 0) return "no episodes";
  if (!std::isfinite(m.mean) || !std::isfinite(m.std)) return "non-finite value";
  return nullptr;
}

const char* Validate(const rlmsg::stats_actor_t& m) {
  return HeaderOk(m.header) ? nullptr : "bad header";
}
const char* Validate(const rlmsg::stats_replay_t& m) {
  return HeaderOk(m.header) ? nullptr : "bad header";
}
const char* Validate(const rlmsg::stats_learner_t& m) {
  return HeaderOk(m.header) ? nullptr : "bad header";
}
const char* Validate(const rlmsg::stats_evaluator_t& m) {
  return HeaderOk(m.header) ? nullptr : "bad header";
}

}  // namespace rl
