// The replay services whose snapshots fuzz_snapshot loads and fuzz_seeds writes: small flat
// (uniform and prioritized) and pixel tables, each on its own in-process bus (a service cannot
// leave a bus), and the traffic that fills them (seeds) or that a restarted replay serves first
// (after a restore, in the fuzz target).
#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "common/lcm_bus.h"
#include "replay/replay_service.h"
#include "rlmsg/sample_batch_t.hpp"
#include "rlmsg/transition_batch_t.hpp"

namespace rl::fuzz {

/// Service configurations; the first byte of a fuzz_snapshot input selects one (modulo).
inline constexpr int kNumReplayConfigs = 3;

/// The batches Fill() inserts: transitions first .. first + count - 1 of `actor`, of
/// configuration `config`'s kind (common/message_examples.h: 2 floats and a width-1 action, or
/// 2 x 2 frames in stacks of two with their new frames).
rlmsg::transition_batch_t SetupBatch(int config, int first, int count, int32_t actor);

class Replica {
 public:
  /// A fresh service of configuration `config` (0 flat uniform, 1 flat prioritized, 2 pixels)
  /// on a memq:// bus of run 42.
  explicit Replica(int config);
  replay::ReplayService& service() { return *service_; }

  /// Inserts `batches` batches of 5 transitions of the configuration's kind from three actors
  /// (past the capacity of 48 from 10 batches on), then requests `samples` batches of 4 and
  /// sends priorities for them.
  void Fill(int batches, int samples);

  /// Delivers `bytes`, a transition batch's encoding, on RL_TRANSITIONS as fuzz::Deliver does
  /// (with a valid header from sender "actor-fuzz" when it decodes).
  void DeliverTransitions(std::string_view bytes);

 private:
  template <class Msg>
  void Publish(const std::string& channel, Msg m, const std::string& sender);

  int config_;
  Bus bus_;
  std::unique_ptr<replay::ReplayService> service_;
  std::map<std::string, int64_t> seq_;
  int64_t fuzz_seq_ = 0;
  std::vector<rlmsg::sample_batch_t> replies_;
};

}  // namespace rl::fuzz
