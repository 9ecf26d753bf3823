#include "learner/batch_decoder.h"

#include <stdexcept>
#include <string>

#include "nn/pixels.h"

namespace rl::learner {

BatchDecoder::BatchDecoder(const envs::EnvSpec& spec, int augment_shift, uint64_t seed)
    : spec_(spec), augment_shift_(augment_shift), rng_(seed) {
  if (augment_shift < 0) throw std::invalid_argument("augment-shift must be >= 0");
  if (augment_shift > 0 && spec.frame_stack <= 0) {
    throw std::invalid_argument("augment-shift applies to pixel envs, and " + spec.id +
                                " is not one");
  }
}

void BatchDecoder::Shifted(const std::vector<uint8_t>& pixels, int n, nn::Matrix* out) {
  std::uniform_int_distribution<int> offset(-augment_shift_, augment_shift_);
  shift_y_.resize(static_cast<size_t>(n));
  shift_x_.resize(static_cast<size_t>(n));
  for (int i = 0; i < n; ++i) {
    shift_y_[static_cast<size_t>(i)] = offset(rng_);
    shift_x_[static_cast<size_t>(i)] = offset(rng_);
  }
  nn::ShiftedPixelsToMatrix(pixels.data(), spec_.frame_stack, spec_.frame_height, spec_.frame_width,
                            n, shift_y_.data(), shift_x_.data(), out);
}

const char* BatchDecoder::Decode(const rlmsg::sample_batch_t& m, Batch* out) {
  const int n = m.count;
  if (n < 1) return "empty batch";
  if (m.action_width != spec_.action_width() ||
      static_cast<int64_t>(m.action.size()) != int64_t{n} * m.action_width) {
    return "action width differs from the env's";
  }
  const int obs_size = spec_.observation_size;
  if (spec_.frame_stack > 0) {
    if (m.stack != spec_.frame_stack || m.height != spec_.frame_height ||
        m.width != spec_.frame_width ||
        static_cast<int64_t>(m.obs_pixels.size()) != int64_t{n} * obs_size ||
        m.next_obs_pixels.size() != m.obs_pixels.size()) {
      return "pixel geometry differs from the env's";
    }
    if (augment_shift_ > 0) {
      Shifted(m.obs_pixels, n, &obs_);
      Shifted(m.next_obs_pixels, n, &next_obs_);
    } else {
      nn::PixelsToMatrix(m.obs_pixels.data(), obs_size, n, &obs_);
      nn::PixelsToMatrix(m.next_obs_pixels.data(), obs_size, n, &next_obs_);
    }
  } else {
    if (m.obs_size != obs_size || static_cast<int64_t>(m.obs.size()) != int64_t{n} * obs_size ||
        m.next_obs.size() != m.obs.size()) {
      return "observation size differs from the env's";
    }
    obs_ = Eigen::Map<const nn::Matrix>(m.obs.data(), obs_size, n);
    next_obs_ = Eigen::Map<const nn::Matrix>(m.next_obs.data(), obs_size, n);
  }
  out->count = n;
  out->action_width = m.action_width;
  out->obs = &obs_;
  out->next_obs = &next_obs_;
  out->action = m.action;
  out->reward = m.reward;
  out->discount = m.discount;
  out->weight = m.weight;
  return nullptr;
}

}  // namespace rl::learner
