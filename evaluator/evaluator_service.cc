#include "evaluator/evaluator_service.h"

#include <algorithm>
#include <cmath>
#include <exception>
#include <filesystem>
#include <limits>
#include <set>
#include <stdexcept>
#include <system_error>

#include "common/atomic_file.h"
#include "common/channels.h"
#include "common/clock.h"
#include "common/shutdown.h"
#include "common/text_format.h"
#include "envs/specs.h"
#include "evaluator/announced_checkpoint.h"
#include "evaluator/tsne_map.h"
#include "evaluator/video.h"
#include "nn/checkpoint.h"
#include "rlmsg/eval_result_t.hpp"
#include "rlmsg/stats_evaluator_t.hpp"

namespace rl::evaluator {
namespace {

namespace fs = std::filesystem;

// The name of the run folder `dir` ("runs/cartpole-1/" -> "cartpole-1").
std::string FolderName(const std::string& dir) {
  std::error_code ec;
  fs::path p = fs::absolute(dir, ec).lexically_normal();
  if (ec) p = fs::path(dir).lexically_normal();
  if (p.filename().empty()) p = p.parent_path();
  return p.filename().string();
}

// `config` when it is valid for a service; throws std::invalid_argument otherwise.
EvaluatorConfig Validated(EvaluatorConfig config) {
  config.Validate();
  // LookupSpec throws for an unknown id.
  if (config.tsne > 0 && envs::LookupSpec(config.env_id).frame_height <= 0) {
    throw std::invalid_argument("tsne needs a pixel env (its maps show camera frames); " +
                                config.env_id + " has none");
  }
  return config;
}

// What every report of the run shows: env, run, goal (by default the env's reward threshold),
// config, how checkpoints are scored, the second metric, and the run folder's other files.
ReportInfo RunReportInfo(const EvaluatorConfig& c, int64_t run_id) {
  const envs::EnvSpec spec = envs::LookupSpec(c.env_id);
  ReportInfo info;
  info.env_id = c.env_id;
  info.run_name = c.run_name.empty() && !c.out_dir.empty() ? FolderName(c.out_dir) : c.run_name;
  info.run_id = run_id;
  info.goal = std::isnan(c.goal) ? spec.reward_threshold : c.goal;
  info.run_config = c.run_config_text;
  const uint64_t last_seed = c.seed_base + static_cast<uint64_t>(c.episodes) - 1;
  info.eval_settings = "Each checkpoint is scored on " + std::to_string(c.episodes) +
                       " episodes (seeds " + std::to_string(c.seed_base) + " to " +
                       std::to_string(last_seed) + ")" +
                       (spec.continuous() ? std::string(" with the actor's action, without noise")
                                          : " with epsilon " + FormatDouble("%g", c.epsilon)) +
                       "; returns G are discounted with gamma " + FormatDouble("%g", c.gamma) + ".";
  if (c.ensemble > 1) {
    const bool weights = c.ensemble_by == "weights";
    info.eval_settings +=
        std::string(weights ? " An average of " : " An ensemble of ") + std::to_string(c.ensemble) +
        (weights ? " is the network whose weights are the mean of a checkpoint's and the "
                 : " is the mean action of a checkpoint and the ") +
        std::to_string(c.ensemble - 1) + " before it, scored on the same episodes" +
        (std::isfinite(c.ensemble_min_mean) ? " for checkpoints whose own mean is at least " +
                                                  FormatDouble("%g", c.ensemble_min_mean)
                                            : std::string()) +
        ".";
  }
  if (!c.second_env.empty()) {
    info.second_name = (c.second_name.empty() ? c.second_env : c.second_name) + ", " +
                       std::to_string(c.second_episodes) + " episodes";
    if (std::isfinite(c.second_min_mean)) {
      info.second_name +=
          ", for a standard mean of " + FormatDouble("%g", c.second_min_mean) + " or more";
    }
  }
  if (!c.out_dir.empty()) {
    info.metrics_file = (fs::path(c.out_dir) / "metrics.jsonl").string();
    info.restarts_file = (fs::path(c.out_dir) / "restarts").string();
  }
  return info;
}

// The run folder's history (creating the folder), or one in memory without a folder.
EvalHistory OpenHistory(const std::string& out_dir) {
  if (out_dir.empty()) return EvalHistory();
  std::error_code ec;
  fs::create_directories(out_dir, ec);
  if (ec) throw std::runtime_error("cannot create '" + out_dir + "': " + ec.message());
  return EvalHistory((fs::path(out_dir) / "eval.jsonl").string());
}

// The best mean of the history an earlier life left (-infinity for none): the bar a new best
// must pass for its second metric, media and t-SNE map.
double BestBefore(const EvalHistory& history) {
  const EvalRecord* best = history.best();
  return best != nullptr ? best->mean : -std::numeric_limits<double>::infinity();
}

std::string ReportDir(const std::string& out_dir) {
  return out_dir.empty() ? "" : (fs::path(out_dir) / "report").string();
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
    if (std::isnan(second_min_mean)) throw std::invalid_argument("second-min-mean is NaN");
    if (second_episodes < 1) {
      throw std::invalid_argument("second-episodes must be at least 1, got " +
                                  std::to_string(second_episodes));
    }
    if (!envs::SameShape(envs::LookupSpec(env_id), envs::LookupSpec(second_env))) {
      throw std::invalid_argument("second-env " + second_env +
                                  " does not take the observations and actions of " + env_id);
    }
  }
  if (screen_episodes < 0 || screen_episodes >= episodes) {
    throw std::invalid_argument("screen-episodes must be 0 (no screen) or 1 to episodes - 1 (" +
                                std::to_string(episodes - 1) + "), got " +
                                std::to_string(screen_episodes));
  }
  if (!(screen_margin >= 0.0) || std::isinf(screen_margin)) {
    throw std::invalid_argument("screen-margin must be finite and at least 0");
  }
  if (ensemble < 1) {
    throw std::invalid_argument("ensemble must be at least 1 (1: no ensembles), got " +
                                std::to_string(ensemble));
  }
  if (ensemble_by != "actions" && ensemble_by != "weights") {
    throw std::invalid_argument(
        "ensemble-by must be 'actions' (the mean action) or 'weights' "
        "(the mean weights), got '" +
        ensemble_by + "'");
  }
  if (ensemble > 1 && ensemble_by == "actions" && !envs::LookupSpec(env_id).continuous()) {
    throw std::invalid_argument(
        "ensemble by actions needs continuous actions (the members' mean action); " + env_id +
        " has discrete ones (ensemble-by = weights averages the networks instead)");
  }
  if (std::isnan(ensemble_min_mean)) throw std::invalid_argument("ensemble-min-mean is NaN");
  if (backlog < 0) {
    throw std::invalid_argument("backlog must be at least 0, got " + std::to_string(backlog));
  }
  if (screen_max_rejects < 1) {
    throw std::invalid_argument("screen-max-rejects must be at least 1, got " +
                                std::to_string(screen_max_rejects));
  }
  if (tsne != 0 && (tsne < kTsneMapMinStates || tsne > kTsneMapMaxStates)) {
    throw std::invalid_argument("tsne must be 0 (no map) or " + std::to_string(kTsneMapMinStates) +
                                " to " + std::to_string(kTsneMapMaxStates) + " states, got " +
                                std::to_string(tsne));
  }
}

EvaluatorService::EvaluatorService(EvaluatorConfig config, Bus* bus, std::FILE* progress)
    : config_(Validated(std::move(config))),
      bus_(bus),
      log_(progress),
      report_dir_(ReportDir(config_.out_dir)),
      report_(RunReportInfo(config_, bus->config().run_id)),
      history_(OpenHistory(config_.out_dir)),
      second_({config_.second_env, config_.second_episodes, config_.epsilon, config_.seed_base,
               config_.gamma, config_.second_min_mean, BestBefore(history_)},
              log_),
      media_({config_.env_id, config_.seed_base, config_.video_width, config_.video_height,
              config_.video_fps, report_dir_, BestBefore(history_)}),
      tsne_({config_.env_id, config_.tsne, config_.seed_base, config_.gamma, report_dir_,
             BestBefore(history_)},
            log_) {
  if (!report_dir_.empty()) {
    // An earlier life killed while it wrote a report file or a video left its temporary file.
    RemoveStaleTemporaries(report_dir_);
    std::error_code ec;
    fs::remove(VideoTemporaryPath((fs::path(report_dir_) / kBestVideo).string()), ec);
  }
  if (!history_.records().empty() || history_.skipped_lines() > 0) {
    log_("evaluator: resumed %zu records from %s (%d unreadable lines skipped)\n",
         history_.records().size(), history_.path().c_str(), history_.skipped_lines());
  }
  // The bus cannot unsubscribe: after the service is gone, its handler does nothing.
  bus_->Subscribe<rlmsg::checkpoint_t>(channels::kCheckpoint,
                                       [alive = alive_](const rlmsg::checkpoint_t& m) {
                                         if (*alive != nullptr) (*alive)->queue_.Offer(m);
                                       });
  QueueUnscoredCheckpoints();
  WriteReportNow();
  next_stats_time_ = MonoSeconds();
}

EvaluatorService::~EvaluatorService() { *alive_ = nullptr; }

bool EvaluatorService::goal_reached() const {
  const EvalRecord* b = history_.best();
  return b != nullptr && b->mean >= report_.goal;
}

std::string EvaluatorService::CheckpointFolder() const {
  if (config_.out_dir.empty()) return {};
  return (fs::path(config_.out_dir) / "checkpoints").string();
}

void EvaluatorService::QueueUnscoredCheckpoints() {
  const std::string folder = CheckpointFolder();
  std::error_code ec;
  if (folder.empty() || !fs::is_directory(folder, ec)) return;
  std::set<std::string> scored;
  for (const EvalRecord& r : history_.records()) scored.insert(r.checkpoint);
  int queued = 0;
  // The learner's checkpoint files (not its state file, nor a temporary one of a write cut short).
  for (const std::string& path : nn::CheckpointFilesIn(folder)) {
    if (scored.count(fs::path(path).filename().string()) > 0) continue;
    rlmsg::checkpoint_t unscored{};
    try {
      const nn::Checkpoint ckpt = ReadAnnouncedCheckpoint(path, folder);
      if (ckpt.meta.run_id != static_cast<uint64_t>(bus_->config().run_id)) continue;
      unscored.path = path;
      unscored.update = ckpt.meta.update;
      unscored.env_steps = ckpt.meta.env_steps;
      unscored.wall_seconds = ckpt.meta.wall_seconds;
    } catch (const std::exception& e) {
      LogError(std::string("not queued: ") + e.what());
      continue;
    }
    if (queue_.Offer(unscored) != CheckpointQueue::Outcome::kDuplicate) ++queued;
  }
  if (queued > 0) {
    std::string over;
    if (queue_.skipped() > 0) {
      over = ", " + std::to_string(queue_.skipped()) + " of them beyond the backlog skipped";
    }
    log_("evaluator: %d unscored checkpoints found in %s%s\n", queued, folder.c_str(),
         over.c_str());
  }
}

bool EvaluatorService::Poll(int timeout_ms) {
  // Wait no longer than until the next stats message.
  const double until_stats = next_stats_time_ - MonoSeconds();
  const int stats_ms = until_stats <= 0 ? 0 : static_cast<int>(std::ceil(until_stats * 1000.0));
  bus_->Handle(std::clamp(stats_ms, 0, std::max(timeout_ms, 0)));
  const bool had_pending = queue_.has_pending();
  bool reached = ScorePending();
  // A map left due by the time share is made when the time allows, between checkpoints.
  const bool mapped = !reached && !queue_.has_pending() && MakeDueTsneMap();
  // A superseded checkpoint only when this poll did nothing else, so that the next Handle has
  // brought any newer announcement first.
  if (!had_pending && !mapped && !reached) reached = ScoreFromBacklog();
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

void EvaluatorService::Tick() {
  if (StopRequested()) throw Interrupted{};
  if (MonoSeconds() >= next_stats_time_) PublishStats();
}

std::optional<EvalRecord> EvaluatorService::Score(const rlmsg::checkpoint_t& announced,
                                                  nn::Checkpoint* ckpt) {
  busy_ = true;
  PublishStats();
  // A refused path or file is logged and counted. The file is read once, from the run's
  // checkpoint folder only (announced_checkpoint.h), and serves every use of the checkpoint.
  EvalRecord record;
  try {
    *ckpt = ReadAnnouncedCheckpoint(announced.path, CheckpointFolder());
    // Stats keep flowing during a long evaluation (a tick after every step: at nice 19 on a busy
    // machine one episode can take longer than the monitor's silence limit), so the monitor
    // never mistakes a busy evaluator for a dead one, and a stop request is honoured after the
    // current step.
    if (!PassesScreen(*ckpt, announced)) {
      busy_ = false;
      return std::nullopt;
    }
    record = ScoreCheckpoint(*ckpt, announced.path, config_.env_id, config_.episodes,
                             config_.epsilon, config_.seed_base, config_.gamma, [this] { Tick(); });
  } catch (const Interrupted&) {
    busy_ = false;
    std::printf("evaluator: stopped during an evaluation; %s is left unscored\n",
                announced.path.c_str());
    std::fflush(stdout);
    return std::nullopt;
  } catch (const std::exception& e) {
    ++refused_;
    busy_ = false;
    LogError(std::string("checkpoint refused: ") + e.what());
    return std::nullopt;
  }
  // The announcement says when the checkpoint was taken.
  record.update = announced.update;
  record.env_steps = announced.env_steps;
  record.wall_seconds = announced.wall_seconds;
  second_.ScoreIfBest(*ckpt, announced.path, &record, [this] { Tick(); });
  ScoreEnsembleIfDue(*ckpt, announced.path, &record);
  busy_ = false;
  return record;
}

void EvaluatorService::ScoreEnsembleIfDue(const nn::Checkpoint& ckpt, const std::string& path,
                                          EvalRecord* record) {
  if (config_.ensemble <= 1 || record->mean < config_.ensemble_min_mean) return;
  EvalRecord ensemble;
  int64_t oldest = 0;
  try {
    const std::vector<std::string> paths = EnsembleFiles(path, config_.ensemble);
    std::vector<nn::Checkpoint> members = {ckpt};
    for (size_t k = 1; k < paths.size(); ++k) {
      members.push_back(ReadAnnouncedCheckpoint(paths[k], CheckpointFolder()));
      if (members.back().meta.run_id != ckpt.meta.run_id) {
        throw std::runtime_error(paths[k] + " is of run " +
                                 std::to_string(members.back().meta.run_id) + ", not " +
                                 std::to_string(ckpt.meta.run_id));
      }
    }
    if (config_.ensemble_by == "weights") {
      const nn::Checkpoint average = AverageCheckpoints(members, paths);
      ensemble = ScoreCheckpoint(average, path, config_.env_id, config_.episodes, config_.epsilon,
                                 config_.seed_base, config_.gamma, [this] { Tick(); });
      KeepAverageIfBest(average, ensemble.mean);
    } else {
      ensemble = ScoreEnsemble(members, paths, config_.env_id, config_.episodes, config_.seed_base,
                               config_.gamma, [this] { Tick(); });
    }
    oldest = members.back().meta.update;
  } catch (const Interrupted&) {
    return;
  } catch (const std::exception& e) {
    log_("evaluator: update %lld: no ensemble of %d: %s\n", static_cast<long long>(record->update),
         config_.ensemble, e.what());
    return;
  }
  record->ensemble_size = config_.ensemble;
  record->ensemble_by = config_.ensemble_by;
  record->ensemble_from = oldest;
  record->ensemble_mean = ensemble.mean;
  record->ensemble_std = ensemble.std;
  record->ensemble_min = ensemble.min;
  record->ensemble_max = ensemble.max;
  record->ensemble_returns = ensemble.returns;
  log_(
      "evaluator: update %lld: %s of %d (updates %lld to %lld): mean %.2f \xC2\xB1 %.1f "
      "(min %g, max %g, %.2f s)\n",
      static_cast<long long>(record->update),
      config_.ensemble_by == "weights" ? "average" : "ensemble", config_.ensemble,
      static_cast<long long>(record->ensemble_from), static_cast<long long>(record->update),
      ensemble.mean, ensemble.std, ensemble.min, ensemble.max, ensemble.eval_seconds);
}

void EvaluatorService::KeepAverageIfBest(const nn::Checkpoint& average, double mean) {
  if (config_.out_dir.empty()) return;
  for (const EvalRecord& r : history_.records()) {
    if (r.ensemble_size > 0 && r.ensemble_by == "weights" && r.ensemble_mean >= mean) return;
  }
  const std::string file = (std::filesystem::path(config_.out_dir) / kBestAverageFile).string();
  try {
    nn::SaveCheckpoint(file, average);
  } catch (const std::exception& e) {
    LogError(e.what());
  }
}

bool EvaluatorService::PassesScreen(const nn::Checkpoint& ckpt,
                                    const rlmsg::checkpoint_t& announced) {
  const EvalRecord* best = history_.best();
  if (config_.screen_episodes == 0 || best == nullptr ||
      rejects_in_row_ >= config_.screen_max_rejects) {
    rejects_in_row_ = 0;
    return true;
  }
  const EvalRecord screen =
      ScoreCheckpoint(ckpt, announced.path, config_.env_id, config_.screen_episodes,
                      config_.epsilon, config_.seed_base, config_.gamma, [this] { Tick(); });
  const double bar = best->mean - config_.screen_margin;
  if (screen.mean >= bar) {
    rejects_in_row_ = 0;
    return true;
  }
  ++screened_out_;
  ++rejects_in_row_;
  log_(
      "evaluator: update %lld, env steps %lld: screened out, not scored (mean of %d episodes "
      "%.2f < best %.2f less margin %g, %.2f s)\n",
      static_cast<long long>(announced.update), static_cast<long long>(announced.env_steps),
      screen.episodes, screen.mean, best->mean, config_.screen_margin, screen.eval_seconds);
  return false;
}

bool EvaluatorService::ScorePending() {
  const std::optional<rlmsg::checkpoint_t> announced = queue_.Take();
  return announced && ScoreAnnounced(*announced);
}

bool EvaluatorService::ScoreFromBacklog() {
  const std::optional<rlmsg::checkpoint_t> announced = queue_.TakeFromBacklog();
  return announced && ScoreAnnounced(*announced);
}

bool EvaluatorService::ScoreAnnounced(const rlmsg::checkpoint_t& announced) {
  nn::Checkpoint ckpt;
  const std::optional<EvalRecord> record = Score(announced, &ckpt);
  if (!record) return false;
  const bool reached = record->mean >= report_.goal;
  ++scored_;
  // Persist the history line first, then the media of a new best and the report.
  try {
    history_.Add(*record);
  } catch (const std::exception& e) {
    LogError(e.what());
  }
  if (config_.videos && !report_dir_.empty()) {
    try {
      media_.RecordIfBest(ckpt, announced.path, *record, [this] { Tick(); });
    } catch (const Interrupted&) {
      // A stop during the video: the result is still announced and reported, without it.
    }
  }
  tsne_.OfferBest(ckpt, announced.path, *record);
  // At the goal the run may end as soon as the result is out: a quick map goes first.
  if (reached && tsne_.due() && tsne_.quick()) MakeTsneMap();
  WriteReportNow();
  Announce(announced, *record, reached);
  MakeDueTsneMap();
  return reached;
}

void EvaluatorService::Announce(const rlmsg::checkpoint_t& announced, const EvalRecord& record,
                                bool reached) {
  rlmsg::eval_result_t result{};
  result.checkpoint = announced.path;
  result.update = record.update;
  result.env_steps = record.env_steps;
  result.wall_seconds = record.wall_seconds;
  result.mean = record.mean;
  result.std = record.std;
  result.min = record.min;
  result.max = record.max;
  result.episodes = record.episodes;
  result.goal_reached = reached ? 1 : 0;
  bus_->Publish(channels::kEval, &result);
  log_(
      "evaluator: update %lld, env steps %lld, wall %.1f s: mean %.2f \xC2\xB1 %.1f "
      "(min %g, max %g, %d episodes, %.2f s)%s\n",
      static_cast<long long>(record.update), static_cast<long long>(record.env_steps),
      record.wall_seconds, record.mean, record.std, record.min, record.max, record.episodes,
      record.eval_seconds, reached ? ", goal reached" : "");
}

bool EvaluatorService::MakeTsneMap() {
  busy_ = true;
  PublishStats();
  const bool written = tsne_.Make([this] { Tick(); });
  busy_ = false;
  return written;
}

bool EvaluatorService::MakeDueTsneMap() {
  if (!tsne_.due() || StopRequested() || !tsne_.fits_share()) return false;
  if (MakeTsneMap()) WriteReportNow();
  return true;
}

void EvaluatorService::WriteReportNow() {
  if (report_dir_.empty()) return;
  ReportInfo info = report_;
  media_.AddTo(&info);
  tsne_.AddTo(&info);
  info.checkpoints_skipped = queue_.skipped();
  info.checkpoints_refused = refused_;
  try {
    WriteReport(report_dir_, history_.records(), info);
  } catch (const std::exception& e) {
    LogError(std::string("cannot write the report: ") + e.what());
  }
}

void EvaluatorService::PublishStats() {
  rlmsg::stats_evaluator_t s{};
  s.checkpoints_scored = scored_;
  s.checkpoints_skipped = queue_.skipped();
  s.checkpoints_refused = refused_;
  s.last_mean = scored_ > 0 ? history_.records().back().mean : 0.0;
  const EvalRecord* b = best();
  s.best_mean = b != nullptr ? b->mean : 0.0;
  s.best_update = b != nullptr ? b->update : -1;
  s.busy = busy_ ? 1 : 0;
  bus_->FillCounters(&s);
  bus_->Publish(channels::kStatsEvaluator, &s);
  next_stats_time_ = MonoSeconds() + config_.stats_period_seconds;
}

std::string EvaluatorService::FinalLine() const {
  if (goal_reached()) return "evaluator: goal reached";
  const EvalRecord* b = best();
  if (b == nullptr) return "evaluator: goal not reached (no checkpoint scored)";
  return "evaluator: goal not reached (best " + rl::Score(b->mean) + ")";
}

}  // namespace rl::evaluator
