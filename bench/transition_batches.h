// Transition batches as actors build them, for the benchmarks that publish them: a CartPole-size
// flat batch, and one actor's stream of Nature-DQN-size pixel batches (84 x 84 frames, stacks of
// 4, each frame sent once).
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <random>
#include <vector>

#include "common/check.h"
#include "common/message_examples.h"
#include "rlmsg/transition_batch_t.hpp"

namespace rl::bench {

constexpr int kHeight = 84;
constexpr int kWidth = 84;
constexpr int kStack = 4;
constexpr int kFrameBytes = kHeight * kWidth;  // 7056
constexpr int kBatch = 32;                     // transitions per actor batch and per sample

// Episodes last between these many steps (uniformly), which decides how often a reset frame is
// sent (one frame per step plus one per episode).
constexpr int kMinEpisode = 200;
constexpr int kMaxEpisode = 1800;

// One actor's stream of pixel batches, as actor/actor.cc builds them with n-step 1: every step
// adds one new frame, an episode's first frame fills its first stack, and a transition names its
// stack and next stack by frame ids, oldest first. Frame contents are random bytes (the replay
// never looks at them).
class PixelActorSim {
 public:
  PixelActorSim(int32_t actor_id, uint64_t seed)
      : rng_(seed), pattern_(static_cast<size_t>(2 * kBatch * kFrameBytes)) {
    for (uint8_t& b : pattern_) b = static_cast<uint8_t>(rng_() >> 56);
    m_.actor_id = actor_id;
    m_.height = kHeight;
    m_.width = kWidth;
    m_.stack = kStack;
    episode_steps_ = EpisodeLength();
  }

  /// The next batch of kBatch transitions with the frames new in it (valid until the next call).
  rlmsg::transition_batch_t* Next() {
    m_.frame_id.clear();
    m_.obs_frames.clear();
    m_.next_obs_frames.clear();
    m_.action.clear();
    m_.reward.clear();
    m_.discount.clear();
    m_.episode_id.clear();
    m_.priority.clear();
    for (int i = 0; i < kBatch; ++i) {
      if (step_ == 0) stack_.fill(AddFrame());  // a reset: the first frame fills the stack
      std::array<int64_t, kStack> next{};
      std::copy(stack_.begin() + 1, stack_.end(), next.begin());
      next.back() = AddFrame();
      const bool terminal = ++step_ >= episode_steps_;
      m_.obs_frames.insert(m_.obs_frames.end(), stack_.begin(), stack_.end());
      m_.next_obs_frames.insert(m_.next_obs_frames.end(), next.begin(), next.end());
      m_.action.push_back(static_cast<float>(rng_() % 18));
      m_.reward.push_back(rng_() % 64 == 0 ? 1.0f : 0.0f);
      m_.discount.push_back(terminal ? 0.0f : 0.99f);
      m_.episode_id.push_back(episode_);
      m_.priority.push_back(0.0f);
      stack_ = next;
      if (terminal) {
        ++episode_;
        step_ = 0;
        episode_steps_ = EpisodeLength();
      }
    }
    m_.num_frames = static_cast<int32_t>(m_.frame_id.size());
    m_.num_bytes = m_.num_frames * kFrameBytes;
    RL_CHECK(static_cast<size_t>(m_.num_bytes) <= pattern_.size()) << "more frames than expected";
    m_.frames.assign(pattern_.begin(), pattern_.begin() + m_.num_bytes);
    m_.count = kBatch;
    m_.num_refs = kBatch * kStack;
    m_.action_width = 1;
    m_.num_action_values = kBatch;
    return &m_;
  }

 private:
  int64_t AddFrame() {
    m_.frame_id.push_back(next_frame_id_);
    return next_frame_id_++;
  }
  int EpisodeLength() {
    return kMinEpisode + static_cast<int>(rng_() % (kMaxEpisode - kMinEpisode + 1));
  }

  std::mt19937_64 rng_;
  std::vector<uint8_t> pattern_;
  rlmsg::transition_batch_t m_{};
  std::array<int64_t, kStack> stack_{};
  int64_t next_frame_id_ = 0;
  int64_t episode_ = 0;
  int step_ = 0;  // steps into the current episode (0: the next step starts one)
  int episode_steps_ = 0;
};

// A batch of 32 CartPole-size transitions (4 floats per observation, one action).
inline rlmsg::transition_batch_t FlatBatch() { return rl::examples::FlatTransitions(0, kBatch, 4); }

}  // namespace rl::bench
