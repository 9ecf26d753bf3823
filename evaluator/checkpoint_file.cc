#include "evaluator/checkpoint_file.h"

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

EvalRecord ScoreCheckpoint(const nn::Checkpoint& ckpt, const std::string& path,
                           const std::string& env_id, int episodes, double epsilon,
                           uint64_t first_seed, double gamma, const Tick& tick, double sigma) {
  const nn::CheckpointMeta& meta = ckpt.meta;
  nn::Sequential net = PolicyNetwork(ckpt, path, env_id);

  // Score.
  const double start = MonoSeconds();
  const EvalScore score =
      ScorePolicy(&net, env_id, episodes, epsilon, first_seed, gamma, tick, sigma);
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
  r.eval_seconds = MonoSeconds() - start;
  if (score.values) {
    r.value_steps = score.values->steps;
    r.value_estimate = score.values->estimate;
    r.value_return = score.values->actual;
    if (std::isfinite(score.values->correlation)) r.value_correlation = score.values->correlation;
  }
  return r;
}

}  // namespace rl::evaluator
