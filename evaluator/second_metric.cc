#include "evaluator/second_metric.h"

#include <exception>

#include "evaluator/checkpoint_file.h"

namespace rl::evaluator {

void SecondMetric::ScoreIfBest(const nn::Checkpoint& ckpt, const std::string& path,
                               EvalRecord* record, const Tick& tick) {
  if (!enabled() || !(record->mean > best_mean_)) return;
  best_mean_ = record->mean;
  if (record->mean < config_.min_mean) return;
  EvalRecord second;
  try {
    second = ScoreCheckpoint(ckpt, path, config_.env_id, config_.episodes, config_.epsilon,
                             config_.seed_base, config_.gamma, tick);
  } catch (const Interrupted&) {
    return;
  } catch (const std::exception& e) {
    LogError(std::string("no second metric: ") + e.what());
    return;
  }
  record->second_mean = second.mean;
  record->second_std = second.std;
  record->second_episodes = second.episodes;
  log_(
      "evaluator: update %lld on the second metric: mean %.2f \xC2\xB1 %.1f (%d episodes, "
      "%.2f s)\n",
      static_cast<long long>(record->update), second.mean, second.std, second.episodes,
      second.eval_seconds);
}

}  // namespace rl::evaluator
