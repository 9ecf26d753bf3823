#include "evaluator/tsne_scheduler.h"

#include <cmath>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <utility>

#include "common/clock.h"
#include "evaluator/checkpoint_file.h"
#include "evaluator/tsne_map.h"

namespace rl::evaluator {
namespace {

// What the report says under the map.
std::string Caption(const EvalRecord& record, const StateSamples& samples, const TsneMapResult& map,
                    int iterations, uint64_t seed_base, double gamma) {
  char gamma_text[32];
  std::snprintf(gamma_text, sizeof(gamma_text), "%g", gamma);
  const std::string colour =
      samples.value_is_return
          ? std::string("the discounted return (gamma ") + gamma_text +
                ") that followed the state in its episode, as the checkpoint holds the actor "
                "network only, which has no value estimate (in an episode cut by its time "
                "limit, the return up to the cut: short of the truth near the cut)"
          : std::string("the network's value estimate of the state, max_a Q(s, a)");
  char distinct[96] = "";
  if (map.distinct < map.states) {
    std::snprintf(distinct, sizeof(distinct),
                  " (%d distinct: a state seen k times is a disc of up to 9 times the area)",
                  map.distinct);
  }
  char caption[1536];
  std::snprintf(
      caption, sizeof(caption),
      "The last hidden layer of %s (update %lld, evaluation mean %.2f) as in Mnih et al. 2015, "
      "Figure 4: the %d activations (the input of its %s layer) in %d states%s of %d greedy "
      "episodes (epsilon 0, seeds from %llu), embedded in 2-D with t-SNE (van der Maaten and "
      "Hinton 2008; perplexity %.3g, %d iterations, KL divergence %.2f). States the network "
      "represents alike lie close together. Colour: %s, from %.3g to %.3g. Beside the map, "
      "the newest input frame of %zu states from the lowest to the highest value, each joined "
      "to its point (ringed).",
      record.checkpoint.c_str(), static_cast<long long>(record.update), record.mean, map.features,
      samples.layer_description.c_str(), map.states, distinct, map.episodes,
      static_cast<unsigned long long>(seed_base), map.perplexity, iterations, map.kl_divergence,
      colour.c_str(), map.value_min, map.value_max, map.thumbnails.size());
  return caption;
}

}  // namespace

TsneScheduler::TsneScheduler(TsneScheduleConfig config, ProgressLog log)
    : config_(std::move(config)),
      log_(log),
      start_time_(MonoSeconds()),
      best_mean_(config_.best_before) {
  if (std::isfinite(config_.best_before) && !config_.report_dir.empty()) {
    caption_ = ReadCaption(MapPath());
  }
}

std::string TsneScheduler::MapPath() const {
  return (std::filesystem::path(config_.report_dir) / kTsneMap).string();
}

void TsneScheduler::OfferBest(const nn::Checkpoint& ckpt, const std::string& path,
                              const EvalRecord& record) {
  if (config_.states <= 0 || config_.report_dir.empty() || !(record.mean > best_mean_)) return;
  try {
    net_ = PolicyNetwork(ckpt, path, config_.env_id);
    record_ = record;
    best_mean_ = record.mean;
  } catch (const std::exception& e) {
    LogError(std::string("no t-SNE map: ") + e.what());
  }
}

double TsneScheduler::ExpectedSeconds() const {
  return last_seconds_ > 0 ? last_seconds_ : kTsneFirstGuessSeconds;
}

bool TsneScheduler::fits_share() const {
  return seconds_ + ExpectedSeconds() <= kTsneTimeShare * (MonoSeconds() - start_time_);
}

bool TsneScheduler::Make(const Tick& tick) {
  if (!net_) return false;
  const EvalRecord record = record_;
  const double start = MonoSeconds();
  double next_line = start + 2.0;  // progress lines only for a map that takes a while
  // After every step and every 50 iterations: the caller's tick, and a line every 5 s.
  const auto progress = [&](const std::string& line) {
    if (tick) tick();
    if (MonoSeconds() >= next_line) {
      log_("evaluator: t-SNE map of %s: %s (%.0f s)\n", record.checkpoint.c_str(), line.c_str(),
           MonoSeconds() - start);
      next_line = MonoSeconds() + 5.0;
    }
  };
  bool written = false;
  try {
    const StateSamples samples = CollectStates(
        &*net_, config_.env_id, config_.states, config_.seed_base, config_.gamma, [&](int states) {
          progress(std::to_string(states) + " of " + std::to_string(config_.states) + " states");
        });
    const double collected = MonoSeconds();
    const TsneConfig tsne;
    const TsneMapResult map = WriteTsneMap(samples, tsne, MapPath(), [&](const TsneProgress& p) {
      char line[96];
      std::snprintf(line, sizeof(line), "t-SNE iteration %d of %d, KL divergence %.3f", p.iteration,
                    p.iterations, p.kl_divergence);
      progress(line);
    });
    caption_ = Caption(record, samples, map, tsne.iterations, config_.seed_base, config_.gamma);
    WriteCaption(MapPath(), caption_);
    log_(
        "evaluator: t-SNE map of %s (update %lld): %d states of %d greedy episodes (%d "
        "distinct), %d features, KL divergence %.2f (%.1f s: %.1f s playing, %.1f s "
        "embedding)\n",
        record.checkpoint.c_str(), static_cast<long long>(record.update), map.states, map.episodes,
        map.distinct, map.features, map.kl_divergence, MonoSeconds() - start, collected - start,
        MonoSeconds() - collected);
    written = true;
    net_.reset();
  } catch (const Interrupted&) {
    log_("evaluator: stopped during the t-SNE map of %s\n", record.checkpoint.c_str());
  } catch (const std::exception& e) {
    LogError(std::string("no t-SNE map: ") + e.what());
    net_.reset();
  }
  const double seconds = MonoSeconds() - start;
  seconds_ += seconds;
  if (written) last_seconds_ = seconds;
  return written;
}

void TsneScheduler::AddTo(ReportInfo* info) const {
  if (caption_.empty()) return;
  info->tsne_file = kTsneMap;
  info->tsne_caption = caption_;
}

}  // namespace rl::evaluator
