#include "evaluator/checkpoint_file.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <random>
#include <stdexcept>

#include "common/clock.h"
#include "envs/specs.h"

namespace rl::evaluator {

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

nn::Sequential LoadPolicyNetwork(const std::string& path, const std::string& env_id,
                                 nn::CheckpointMeta* meta) {
  const nn::Checkpoint ckpt = nn::LoadCheckpoint(path);
  if (meta != nullptr) *meta = ckpt.meta;
  return PolicyNetwork(ckpt, path, env_id);
}

EvalRecord ScoreCheckpointFile(const std::string& path, const std::string& env_id, int episodes,
                               double epsilon, uint64_t first_seed, double gamma, const Tick& tick,
                               double sigma) {
  return ScoreCheckpoint(nn::LoadCheckpoint(path), path, env_id, episodes, epsilon, first_seed,
                         gamma, tick, sigma);
}

namespace {

// The record of checkpoint `path` (its metadata `meta`) scored `score` in `seconds`.
EvalRecord Record(const std::string& path, const nn::CheckpointMeta& meta, const EvalScore& score,
                  double seconds) {
  EvalRecord r;
  r.checkpoint = std::filesystem::path(path).filename().string();
  r.update = meta.update;
  r.env_steps = meta.env_steps;
  r.wall_seconds = meta.wall_seconds;
  r.mean = score.mean;
  r.std = score.std;
  r.min = score.min;
  r.max = score.max;
  r.episodes = score.episodes;
  r.returns = score.returns;
  r.steps = score.steps;
  r.action_mean = score.action_mean;
  r.eval_seconds = seconds;
  if (score.values) {
    r.value_steps = score.values->steps;
    r.value_estimate = score.values->estimate;
    r.value_return = score.values->actual;
    if (std::isfinite(score.values->correlation)) r.value_correlation = score.values->correlation;
  }
  return r;
}

}  // namespace

EvalRecord ScoreCheckpoint(const nn::Checkpoint& ckpt, const std::string& path,
                           const std::string& env_id, int episodes, double epsilon,
                           uint64_t first_seed, double gamma, const Tick& tick, double sigma) {
  nn::Sequential net = PolicyNetwork(ckpt, path, env_id);
  const double start = MonoSeconds();
  const EvalScore score =
      ScorePolicy(&net, env_id, episodes, epsilon, first_seed, gamma, tick, sigma);
  return Record(path, ckpt.meta, score, MonoSeconds() - start);
}

std::vector<std::string> EnsembleFiles(const std::string& path, int count) {
  if (count < 1) throw std::invalid_argument("an ensemble needs at least 1 checkpoint");
  namespace fs = std::filesystem;
  const fs::path given = fs::absolute(path).lexically_normal();
  const std::vector<std::string> files = nn::CheckpointFilesIn(given.parent_path().string());
  const auto it = std::find_if(files.begin(), files.end(), [&](const std::string& f) {
    return fs::path(f).lexically_normal() == given;
  });
  if (it == files.end()) {
    throw std::runtime_error(path + " is not a checkpoint file of its folder (ckpt-<update>.bin)");
  }
  const auto before = it - files.begin();
  if (before + 1 < count) {
    throw std::runtime_error("an ensemble of " + std::to_string(count) + " needs " +
                             std::to_string(count - 1) + " checkpoints before " + path +
                             " in its folder; it has " + std::to_string(before));
  }
  std::vector<std::string> chosen;
  for (int k = 0; k < count; ++k) chosen.push_back(*(it - k));
  return chosen;
}

EvalRecord ScoreEnsemble(const std::vector<nn::Checkpoint>& ckpts,
                         const std::vector<std::string>& paths, const std::string& env_id,
                         int episodes, uint64_t first_seed, double gamma, const Tick& tick) {
  if (ckpts.empty()) throw std::invalid_argument("an ensemble needs at least one checkpoint");
  if (paths.size() != ckpts.size()) {
    throw std::invalid_argument("an ensemble needs a path for each checkpoint");
  }
  std::vector<nn::Sequential> nets;
  for (size_t k = 0; k < ckpts.size(); ++k)
    nets.push_back(PolicyNetwork(ckpts[k], paths[k], env_id));
  const std::unique_ptr<actor::Policy> policy = EnsemblePolicy(nets, envs::LookupSpec(env_id));
  const double start = MonoSeconds();
  const EvalScore score = Score(policy.get(), env_id, episodes, first_seed, gamma, tick);
  return Record(paths.front(), ckpts.front().meta, score, MonoSeconds() - start);
}

nn::Checkpoint AverageCheckpoints(const std::vector<nn::Checkpoint>& ckpts,
                                  const std::vector<std::string>& paths) {
  if (ckpts.empty()) throw std::invalid_argument("an average needs at least one checkpoint");
  if (paths.size() != ckpts.size()) {
    throw std::invalid_argument("an average needs a path for each checkpoint");
  }
  const nn::Checkpoint& newest = ckpts.front();
  std::vector<double> sum(newest.params.begin(), newest.params.end());
  for (size_t k = 1; k < ckpts.size(); ++k) {
    const nn::Checkpoint& c = ckpts[k];
    if (c.architecture != newest.architecture || c.params.size() != newest.params.size()) {
      throw std::runtime_error(paths[k] + " is another network than " + paths[0] +
                               " (architecture '" + c.architecture + "', " +
                               std::to_string(c.params.size()) + " parameters): no average");
    }
    if (c.meta.run_id != newest.meta.run_id) {
      throw std::runtime_error(paths[k] + " is of run " + std::to_string(c.meta.run_id) + ", not " +
                               std::to_string(newest.meta.run_id) + ": no average");
    }
    for (size_t i = 0; i < sum.size(); ++i) sum[i] += c.params[i];
  }
  nn::Checkpoint average = newest;
  const double n = static_cast<double>(ckpts.size());
  for (size_t i = 0; i < sum.size(); ++i) average.params[i] = static_cast<float>(sum[i] / n);
  average.meta.note = "The mean weights of " + std::to_string(ckpts.size()) +
                      " checkpoints, updates " + std::to_string(ckpts.back().meta.update) + " to " +
                      std::to_string(newest.meta.update) + ".\n" + newest.meta.note;
  return average;
}

EvalRecord ScoreEnsembleFiles(const std::vector<std::string>& paths, const std::string& env_id,
                              int episodes, uint64_t first_seed, double gamma) {
  std::vector<nn::Checkpoint> ckpts;
  for (const std::string& path : paths) ckpts.push_back(nn::LoadCheckpoint(path));
  return ScoreEnsemble(ckpts, paths, env_id, episodes, first_seed, gamma);
}

}  // namespace rl::evaluator
