#include "evaluator/evaluator_service.h"

#include "envs/specs.h"
#include "evaluator/announced_checkpoint.h"
#include "evaluator/frame_grid.h"
#include "evaluator/tsne_map.h"
#include "evaluator/video.h"

#include <algorithm>
#include <cmath>
#include <cstdarg>
#include <filesystem>
#include <random>
#include <stdexcept>
#include <system_error>

#include "common/atomic_file.h"
#include "common/channels.h"
#include "common/clock.h"
#include "common/shutdown.h"
#include "common/text_format.h"
#include "envs/registry.h"
#include "envs/specs.h"
#include "nn/checkpoint.h"
#include "nn/sequential.h"
#include "rlmsg/eval_result_t.hpp"
#include "rlmsg/stats_evaluator_t.hpp"

namespace rl::evaluator {
namespace {

// The summary of a score, which EvalScore, EvalRecord and eval_result_t all carry.
template <class From, class To>
void CopySummary(const From& from, To* to) {
  to->mean = from.mean;
  to->std = from.std;
  to->min = from.min;
  to->max = from.max;
  to->episodes = from.episodes;
}

std::string FileName(const std::string& path) {
  return std::filesystem::path(path).filename().string();
}

// The name of the run folder `dir` ("runs/cartpole-1/" -> "cartpole-1").
std::string FolderName(const std::string& dir) {
  std::error_code ec;
  std::filesystem::path p = std::filesystem::absolute(dir, ec).lexically_normal();
  if (ec) p = std::filesystem::path(dir).lexically_normal();
  if (p.filename().empty()) p = p.parent_path();
  return p.filename().string();
}

}  // namespace

void EvaluatorConfig::Validate() const {
  if (env_id.empty()) throw std::invalid_argument("env id must not be empty");
  if (episodes < 1) {
    throw std::invalid_argument("episodes must be at least 1, got " + std::to_string(episodes));
  }
  if (!(epsilon >= 0.0 && epsilon <= 1.0)) {
    throw std::invalid_argument("epsilon must be in [0, 1], got " + std::to_string(epsilon));
  }
  if (!(gamma >= 0.0 && gamma <= 1.0)) {
    throw std::invalid_argument("gamma must be in [0, 1], got " + std::to_string(gamma));
  }
  if (!(stats_period_seconds > 0.0)) {
    throw std::invalid_argument("stats period must be positive");
  }
  if (std::isinf(goal)) throw std::invalid_argument("goal must be finite");
  if (!second_env.empty()) {
    if (second_episodes < 1) {
      throw std::invalid_argument("second-episodes must be at least 1, got " +
                                  std::to_string(second_episodes));
    }
    const envs::EnvSpec a = envs::LookupSpec(env_id), b = envs::LookupSpec(second_env);
    if (a.observation_size != b.observation_size || a.frame_height != b.frame_height ||
        a.frame_width != b.frame_width || a.frame_stack != b.frame_stack ||
        a.num_actions != b.num_actions || a.action_dim != b.action_dim) {
      throw std::invalid_argument("second-env " + second_env +
                                  " does not take the observations and actions of " + env_id);
    }
  }
  if (tsne != 0 && (tsne < kTsneMapMinStates || tsne > kTsneMapMaxStates)) {
    throw std::invalid_argument("tsne must be 0 (no map) or " + std::to_string(kTsneMapMinStates) +
                                " to " + std::to_string(kTsneMapMaxStates) + " states, got " +
                                std::to_string(tsne));
  }
}

nn::Sequential LoadPolicyNetwork(const std::string& path, const std::string& env_id,
                                 nn::CheckpointMeta* meta) {
  const nn::Checkpoint ckpt = nn::LoadCheckpoint(path);
  if (meta != nullptr) *meta = ckpt.meta;
  return PolicyNetwork(ckpt, path, env_id);
}

nn::Sequential PolicyNetwork(const nn::Checkpoint& ckpt, const std::string& path,
                             const std::string& env_id) {
  // Build; every failure is a refusal with a reason.
  std::mt19937 init_rng(0);  // the initial weights are overwritten by the checkpoint's
  nn::Sequential net;
  try {
    net = nn::BuildFromArchitecture(ckpt.architecture, &init_rng);
  } catch (const std::exception& e) {
    throw std::runtime_error("checkpoint " + path + ": cannot build architecture '" +
                             ckpt.architecture + "': " + e.what());
  }
  if (static_cast<int64_t>(ckpt.params.size()) != net.FlatSize()) {
    throw std::runtime_error("checkpoint " + path + ": " + std::to_string(ckpt.params.size()) +
                             " parameters, but architecture '" + ckpt.architecture + "' has " +
                             std::to_string(net.FlatSize()));
  }
  net.SetFlat(ckpt.params.data(), ckpt.params.size());
  const std::string misfit = CheckNetworkFitsEnv(net, envs::LookupSpec(env_id));
  if (!misfit.empty()) throw std::runtime_error("checkpoint " + path + ": " + misfit);
  return net;
}

EvalRecord ScoreCheckpointFile(const std::string& path, const std::string& env_id, int episodes,
                               double epsilon, uint64_t first_seed, double gamma,
                               const std::function<void()>& after_episode) {
  return ScoreCheckpoint(nn::LoadCheckpoint(path), path, env_id, episodes, epsilon, first_seed,
                         gamma, after_episode);
}

EvalRecord ScoreCheckpoint(const nn::Checkpoint& ckpt, const std::string& path,
                           const std::string& env_id, int episodes, double epsilon,
                           uint64_t first_seed, double gamma,
                           const std::function<void()>& after_episode) {
  const nn::CheckpointMeta& meta = ckpt.meta;
  nn::Sequential net = PolicyNetwork(ckpt, path, env_id);

  // Score.
  const double start = MonoSeconds();
  const EvalScore score =
      ScorePolicy(&net, env_id, episodes, epsilon, first_seed, gamma, after_episode);
  EvalRecord r;
  r.checkpoint = FileName(path);
  r.update = meta.update;
  r.env_steps = meta.env_steps;
  r.wall_seconds = meta.wall_seconds;
  CopySummary(score, &r);
  r.eval_seconds = MonoSeconds() - start;
  if (score.values) {
    r.value_steps = score.values->steps;
    r.value_estimate = score.values->estimate;
    r.value_return = score.values->actual;
    if (std::isfinite(score.values->correlation)) r.value_correlation = score.values->correlation;
  }
  return r;
}

EvaluatorService::EvaluatorService(EvaluatorConfig config, Bus* bus, std::FILE* progress)
    : config_(std::move(config)), bus_(bus), progress_(progress) {
  config_.Validate();
  // The goal defaults to the env's reward threshold (LookupSpec throws for an unknown id).
  const envs::EnvSpec spec = envs::LookupSpec(config_.env_id);
  goal_ = std::isnan(config_.goal) ? spec.reward_threshold : config_.goal;
  has_frames_ = spec.frame_height > 0;
  if (config_.tsne > 0 && !has_frames_) {
    throw std::invalid_argument("tsne needs a pixel env (its maps show camera frames); " +
                                config_.env_id + " has none");
  }
  start_time_ = MonoSeconds();
  char epsilon[32], gamma[32];
  std::snprintf(epsilon, sizeof(epsilon), "%g", config_.epsilon);
  std::snprintf(gamma, sizeof(gamma), "%g", config_.gamma);
  const uint64_t last_seed = config_.seed_base + static_cast<uint64_t>(config_.episodes) - 1;
  eval_settings_ = "Each checkpoint is scored on " + std::to_string(config_.episodes) +
                   " episodes (seeds " + std::to_string(config_.seed_base) + " to " +
                   std::to_string(last_seed) + ")" +
                   (spec.continuous() ? std::string(" with the actor's action, without noise")
                                      : std::string(" with epsilon ") + epsilon) +
                   "; returns G are discounted with gamma " + gamma + ".";

  // Resume the history of the run folder.
  if (!config_.out_dir.empty()) {
    std::error_code ec;
    std::filesystem::create_directories(config_.out_dir, ec);
    if (ec) {
      throw std::runtime_error("cannot create '" + config_.out_dir + "': " + ec.message());
    }
    jsonl_path_ = (std::filesystem::path(config_.out_dir) / "eval.jsonl").string();
    report_dir_ = (std::filesystem::path(config_.out_dir) / "report").string();
    // An earlier life killed while it wrote a report file or a video left its temporary file.
    RemoveStaleTemporaries(report_dir_);
    std::filesystem::remove(VideoTemporaryPath(report_dir_ + "/" + kBestVideo), ec);
    run_name_ = config_.run_name.empty() ? FolderName(config_.out_dir) : config_.run_name;
    int skipped_lines = 0;
    records_ = LoadJsonLines(jsonl_path_, &skipped_lines);
    if (!records_.empty() || skipped_lines > 0) {
      Log("evaluator: resumed %zu records from %s (%d unreadable lines skipped)\n", records_.size(),
          jsonl_path_.c_str(), skipped_lines);
    }
    for (const EvalRecord& r : records_) {
      scored_keys_.insert({r.checkpoint, r.update});
      if (r.mean >= goal_) goal_reached_ = true;
    }
  } else {
    run_name_ = config_.run_name;
  }

  // The bus cannot unsubscribe: after the service is gone, its handler does nothing.
  bus_->Subscribe<rlmsg::checkpoint_t>(channels::kCheckpoint,
                                       [alive = alive_](const rlmsg::checkpoint_t& m) {
                                         if (*alive != nullptr) (*alive)->OnCheckpoint(m);
                                       });
  WriteReportNow();
  next_stats_time_ = MonoSeconds();
}

EvaluatorService::~EvaluatorService() { *alive_ = nullptr; }

void EvaluatorService::Log(const char* fmt, ...) const {
  if (progress_ == nullptr) return;
  va_list args;
  va_start(args, fmt);
  std::vfprintf(progress_, fmt, args);
  va_end(args);
  std::fflush(progress_);
}

std::string EvaluatorService::CheckpointFolder() const {
  if (config_.out_dir.empty()) return {};
  return (std::filesystem::path(config_.out_dir) / "checkpoints").string();
}

void EvaluatorService::OnCheckpoint(const rlmsg::checkpoint_t& msg) {
  // A re-announcement of a scored checkpoint changes nothing.
  if (scored_keys_.count({FileName(msg.path), msg.update}) > 0 ||
      (pending_ && pending_->path == msg.path && pending_->update == msg.update)) {
    ++duplicates_;
    return;
  }
  // Keep the newest; the other one is skipped.
  if (pending_ && msg.update < pending_->update) {
    ++skipped_;
    return;
  }
  if (pending_) ++skipped_;
  pending_ = msg;
}

const EvalRecord* EvaluatorService::best() const {
  const EvalRecord* b = nullptr;
  for (const EvalRecord& r : records_) {
    if (b == nullptr || r.mean > b->mean) b = &r;
  }
  return b;
}

bool EvaluatorService::Poll(int timeout_ms) {
  // Wait no longer than until the next stats message.
  const double until_stats = next_stats_time_ - MonoSeconds();
  const int stats_ms = until_stats <= 0 ? 0 : static_cast<int>(std::ceil(until_stats * 1000.0));
  bus_->Handle(std::clamp(stats_ms, 0, std::max(timeout_ms, 0)));
  const bool reached = ScorePending();
  // A map left due by the time share is made when the time allows, between checkpoints.
  if (!reached && !pending_) MakeDueTsneMap();
  if (MonoSeconds() >= next_stats_time_) PublishStats();
  return reached && config_.stop_at_goal;
}

void EvaluatorService::Run() {
  while (!StopRequested()) {
    if (Poll(100)) break;
  }
  WriteReportNow();
  PublishStats();
}

bool EvaluatorService::ScorePending() {
  if (!pending_) return false;
  const rlmsg::checkpoint_t announced = std::move(*pending_);
  pending_.reset();
  busy_ = true;
  PublishStats();

  // Load and score; a refused path or file is logged and counted. The file is read once, from
  // the run's checkpoint folder only (announced_checkpoint.h), and serves every use below.
  EvalRecord record;
  nn::Checkpoint ckpt;
  // Thrown between episodes when a stop was requested: an unfinished evaluation is dropped.
  struct Stopped {};
  try {
    ckpt = ReadAnnouncedCheckpoint(announced.path, CheckpointFolder());
    // Stats keep flowing during a long evaluation (KUKA: about a second per episode), so the
    // monitor never mistakes a busy evaluator for a dead one, and a stop request is honoured
    // after the current episode.
    record = ScoreCheckpoint(ckpt, announced.path, config_.env_id, config_.episodes,
                             config_.epsilon, config_.seed_base, config_.gamma, [this] {
                               if (StopRequested()) throw Stopped{};
                               if (MonoSeconds() >= next_stats_time_) PublishStats();
                             });
  } catch (const Stopped&) {
    busy_ = false;
    std::printf("evaluator: stopped during an evaluation; %s is left unscored\n",
                announced.path.c_str());
    std::fflush(stdout);
    return false;
  } catch (const std::exception& e) {
    ++refused_;
    busy_ = false;
    std::fprintf(stderr, "evaluator: checkpoint refused: %s\n", e.what());
    std::fflush(stderr);
    return false;
  }
  busy_ = false;
  // The announcement says when the checkpoint was taken.
  record.update = announced.update;
  record.env_steps = announced.env_steps;
  record.wall_seconds = announced.wall_seconds;
  // A new best is also scored on the second metric.
  if (!config_.second_env.empty() && record.mean > best_second_mean_) {
    best_second_mean_ = record.mean;
    busy_ = true;
    try {
      const EvalRecord second =
          ScoreCheckpoint(ckpt, announced.path, config_.second_env, config_.second_episodes,
                          config_.epsilon, config_.seed_base, config_.gamma, [this] {
                            if (StopRequested()) throw Stopped{};
                            if (MonoSeconds() >= next_stats_time_) PublishStats();
                          });
      record.second_mean = second.mean;
      record.second_std = second.std;
      record.second_episodes = second.episodes;
      Log("evaluator: update %lld on the second metric: mean %.2f \xC2\xB1 %.1f (%d episodes, "
          "%.2f s)\n",
          static_cast<long long>(record.update), second.mean, second.std, second.episodes,
          second.eval_seconds);
    } catch (const Stopped&) {
      // Stopping: the record keeps its standard score.
    } catch (const std::exception& e) {
      std::fprintf(stderr, "evaluator: no second metric: %s\n", e.what());
      std::fflush(stderr);
    }
    busy_ = false;
  }
  const bool reached = record.mean >= goal_;
  goal_reached_ = goal_reached_ || reached;
  ++scored_;
  last_mean_ = record.mean;
  records_.push_back(record);
  scored_keys_.insert({record.checkpoint, record.update});
  if (config_.videos && !report_dir_.empty() && record.mean > best_video_mean_) {
    RecordVideo(ckpt, announced.path, record);
  }
  // A new best checkpoint's t-SNE map becomes due (replacing an older best's that was not made).
  if (config_.tsne > 0 && !report_dir_.empty() && record.mean > best_tsne_mean_) {
    try {
      tsne_net_ = PolicyNetwork(ckpt, announced.path, config_.env_id);
      tsne_record_ = record;
      best_tsne_mean_ = record.mean;
    } catch (const std::exception& e) {
      std::fprintf(stderr, "evaluator: no t-SNE map: %s\n", e.what());
      std::fflush(stderr);
    }
  }
  // At the goal the run may end as soon as the result is out: a quick map goes first.
  if (reached && tsne_net_ && ExpectedTsneSeconds() <= kTsneGoalSeconds) MakeTsneMap();

  // Persist: the line first (the history), then the report.
  if (!jsonl_path_.empty()) {
    try {
      AppendJsonLine(jsonl_path_, record);
    } catch (const std::exception& e) {
      std::fprintf(stderr, "evaluator: %s\n", e.what());
      std::fflush(stderr);
    }
  }
  WriteReportNow();

  // Announce the result.
  rlmsg::eval_result_t result{};
  result.checkpoint = announced.path;
  result.update = record.update;
  result.env_steps = record.env_steps;
  result.wall_seconds = record.wall_seconds;
  CopySummary(record, &result);
  result.goal_reached = reached ? 1 : 0;
  bus_->Publish(channels::kEval, &result);

  Log("evaluator: update %lld, env steps %lld, wall %.1f s: mean %.2f \xC2\xB1 %.1f "
      "(min %g, max %g, %d episodes, %.2f s)%s\n",
      static_cast<long long>(record.update), static_cast<long long>(record.env_steps),
      record.wall_seconds, record.mean, record.std, record.min, record.max, record.episodes,
      record.eval_seconds, reached ? ", goal reached" : "");
  MakeDueTsneMap();
  return reached;
}

void EvaluatorService::MakeDueTsneMap() {
  if (!tsne_net_ || report_dir_.empty() || StopRequested()) return;
  if (tsne_seconds_ + ExpectedTsneSeconds() > kTsneTimeShare * (MonoSeconds() - start_time_)) {
    return;
  }
  if (MakeTsneMap()) WriteReportNow();
}

double EvaluatorService::ExpectedTsneSeconds() const {
  return last_tsne_seconds_ > 0 ? last_tsne_seconds_ : kTsneFirstGuessSeconds;
}

bool EvaluatorService::MakeTsneMap() {
  if (!tsne_net_) return false;
  const EvalRecord record = tsne_record_;
  const double start = MonoSeconds();
  double next_line = start + 2.0;  // progress lines only for a map that takes a while
  busy_ = true;
  PublishStats();
  struct Stopped {};
  // Between episodes and every 50 iterations: stop requests, stats, and a line every 5 s.
  auto tick = [&](const std::string& line) {
    if (StopRequested()) throw Stopped{};
    if (MonoSeconds() >= next_stats_time_) PublishStats();
    if (MonoSeconds() >= next_line) {
      Log("evaluator: t-SNE map of %s: %s (%.0f s)\n", record.checkpoint.c_str(), line.c_str(),
          MonoSeconds() - start);
      next_line = MonoSeconds() + 5.0;
    }
  };
  bool written = false;
  try {
    const StateSamples samples = CollectStates(
        &*tsne_net_, config_.env_id, config_.tsne, config_.seed_base, config_.gamma,
        [&](int states) {
          tick(std::to_string(states) + " of " + std::to_string(config_.tsne) + " states");
        });
    const double collected = MonoSeconds();
    TsneConfig tsne;
    const TsneMapResult map = WriteTsneMap(
        samples, tsne, (std::filesystem::path(report_dir_) / kTsneMap).string(),
        [&](const TsneProgress& p) {
          char line[96];
          std::snprintf(line, sizeof(line), "t-SNE iteration %d of %d, KL divergence %.3f",
                        p.iteration, p.iterations, p.kl_divergence);
          tick(line);
        });
    const double seconds = MonoSeconds() - start;
    char gamma[32];
    std::snprintf(gamma, sizeof(gamma), "%g", config_.gamma);
    const std::string colour =
        samples.value_is_return
            ? std::string("the discounted return (gamma ") + gamma +
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
        static_cast<unsigned long long>(config_.seed_base), map.perplexity, tsne.iterations,
        map.kl_divergence, colour.c_str(), map.value_min, map.value_max, map.thumbnails.size());
    tsne_caption_ = caption;
    Log("evaluator: t-SNE map of %s (update %lld): %d states of %d greedy episodes (%d "
        "distinct), %d features, KL divergence %.2f (%.1f s: %.1f s playing, %.1f s "
        "embedding)\n",
        record.checkpoint.c_str(), static_cast<long long>(record.update), map.states, map.episodes,
        map.distinct, map.features, map.kl_divergence, seconds, collected - start,
        MonoSeconds() - collected);
    written = true;
    tsne_net_.reset();
  } catch (const Stopped&) {
    Log("evaluator: stopped during the t-SNE map of %s\n", record.checkpoint.c_str());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "evaluator: no t-SNE map: %s\n", e.what());
    std::fflush(stderr);
    tsne_net_.reset();
  }
  busy_ = false;
  const double seconds = MonoSeconds() - start;
  tsne_seconds_ += seconds;
  if (written) last_tsne_seconds_ = seconds;
  return written;
}

void EvaluatorService::RecordVideo(const nn::Checkpoint& ckpt, const std::string& path,
                                   const EvalRecord& record) {
  // One network serves the video and the frame grid.
  nn::Sequential net;
  try {
    net = PolicyNetwork(ckpt, path, config_.env_id);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "evaluator: no video: %s\n", e.what());
    std::fflush(stderr);
    return;
  }
  try {
    const VideoResult v = RecordGreedyVideo(
        &net, config_.env_id, config_.seed_base, config_.video_width, config_.video_height,
        config_.video_fps, (std::filesystem::path(report_dir_) / kBestVideo).string());
    best_video_mean_ = record.mean;
    char caption[256];
    std::snprintf(caption, sizeof(caption),
                  "Greedy episode (epsilon 0, seed %llu) of the best checkpoint, %s (update %lld, "
                  "evaluation mean %s): return %s over %d frames.",
                  static_cast<unsigned long long>(config_.seed_base), record.checkpoint.c_str(),
                  static_cast<long long>(record.update), rl::Score(record.mean).c_str(),
                  rl::Score(v.episode_return).c_str(), v.frames);
    video_caption_ = caption;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "evaluator: no video: %s\n", e.what());
    std::fflush(stderr);
  }
  if (!has_frames_) return;
  try {
    const FrameGridResult g = WriteFrameGrid(
        &net, config_.env_id, config_.seed_base, kFrameGridEpisodes, kFrameGridColumns,
        (std::filesystem::path(report_dir_) / kFrameGrid).string());
    char caption[384];
    std::snprintf(caption, sizeof(caption),
                  "%d greedy episodes (epsilon 0, seeds %llu to %llu) of %s (update %lld), one row "
                  "each: the camera image as rendered (left) and the frame the network receives "
                  "(right) after reset and after every step; mean return %.2f.",
                  g.episodes, static_cast<unsigned long long>(config_.seed_base),
                  static_cast<unsigned long long>(config_.seed_base + g.episodes - 1),
                  record.checkpoint.c_str(), static_cast<long long>(record.update), g.mean_return);
    frames_caption_ = caption;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "evaluator: no frame grid: %s\n", e.what());
    std::fflush(stderr);
  }
}

void EvaluatorService::WriteReportNow() {
  if (report_dir_.empty()) return;
  ReportInfo info;
  info.env_id = config_.env_id;
  info.run_name = run_name_;
  info.run_id = bus_->config().run_id;
  info.goal = goal_;
  if (!video_caption_.empty()) {
    info.video_file = kBestVideo;
    info.video_caption = video_caption_;
  }
  if (!frames_caption_.empty()) {
    info.frames_file = kFrameGrid;
    info.frames_caption = frames_caption_;
  }
  if (!tsne_caption_.empty()) {
    info.tsne_file = kTsneMap;
    info.tsne_caption = tsne_caption_;
  }
  info.run_config = config_.run_config_text;
  info.eval_settings = eval_settings_;
  if (!config_.second_env.empty()) {
    info.second_name = (config_.second_name.empty() ? config_.second_env : config_.second_name) +
                       ", " + std::to_string(config_.second_episodes) + " episodes";
  }
  info.checkpoints_skipped = skipped_;
  info.checkpoints_refused = refused_;
  if (!config_.out_dir.empty()) {
    info.metrics_file = (std::filesystem::path(config_.out_dir) / "metrics.jsonl").string();
    info.restarts_file = (std::filesystem::path(config_.out_dir) / "restarts").string();
  }
  try {
    WriteReport(report_dir_, records_, info);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "evaluator: cannot write the report: %s\n", e.what());
    std::fflush(stderr);
  }
}

void EvaluatorService::PublishStats() {
  rlmsg::stats_evaluator_t s{};
  s.checkpoints_scored = scored_;
  s.checkpoints_skipped = skipped_;
  s.checkpoints_refused = refused_;
  s.last_mean = last_mean_;
  const EvalRecord* b = best();
  s.best_mean = b != nullptr ? b->mean : 0.0;
  s.best_update = b != nullptr ? b->update : -1;
  s.busy = busy_ ? 1 : 0;
  bus_->FillCounters(&s);
  bus_->Publish(channels::kStatsEvaluator, &s);
  next_stats_time_ = MonoSeconds() + config_.stats_period_seconds;
}

std::string EvaluatorService::FinalLine() const {
  if (goal_reached_) return "evaluator: goal reached";
  const EvalRecord* b = best();
  if (b == nullptr) return "evaluator: goal not reached (no checkpoint scored)";
  return "evaluator: goal not reached (best " + rl::Score(b->mean) + ")";
}

}  // namespace rl::evaluator
