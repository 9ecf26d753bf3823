// A checkpoint as the evaluator uses it: built into a policy network that fits the env, and
// scored (scorer.h) into an EvalRecord. From a file given by hand (read wherever it is) or from a
// checkpoint already read (an announced one: announced_checkpoint.h).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "evaluator/eval_history.h"
#include "evaluator/progress.h"
#include "evaluator/scorer.h"
#include "nn/checkpoint.h"
#include "nn/sequential.h"

namespace rl::evaluator {

/// The network of a loaded checkpoint (`path` names it in errors), checked against `env_id`.
/// Throws std::runtime_error with the reason when it is refused: its architecture does not
/// build, its parameters do not fit the architecture, or the network does not fit the env.
nn::Sequential PolicyNetwork(const nn::Checkpoint& ckpt, const std::string& path,
                             const std::string& env_id);

/// Loads a checkpoint file and builds its network (PolicyNetwork); fills *meta when not null.
/// Throws std::runtime_error with the reason when the file is refused (see ScoreCheckpointFile).
nn::Sequential LoadPolicyNetwork(const std::string& path, const std::string& env_id,
                                 nn::CheckpointMeta* meta = nullptr);

/// Builds the network of a loaded checkpoint (PolicyNetwork) and scores it on `env_id` (see
/// ScorePolicy), with its value estimates against the returns (discount gamma). `path` names
/// the checkpoint in the record and in errors. The record's update, env_steps and wall_seconds
/// come from the checkpoint's metadata. Throws std::runtime_error as PolicyNetwork.
/// `tick` and `sigma` as in ScorePolicy.
EvalRecord ScoreCheckpoint(const nn::Checkpoint& ckpt, const std::string& path,
                           const std::string& env_id, int episodes, double epsilon,
                           uint64_t first_seed, double gamma = kDefaultGamma, const Tick& tick = {},
                           double sigma = 0.0);

/// Loads a checkpoint file and scores it (ScoreCheckpoint). Throws std::runtime_error with the
/// reason when the file is refused: it does not load (missing, truncated, corrupted, foreign),
/// or ScoreCheckpoint refuses it.
EvalRecord ScoreCheckpointFile(const std::string& path, const std::string& env_id, int episodes,
                               double epsilon, uint64_t first_seed, double gamma = kDefaultGamma,
                               const Tick& tick = {}, double sigma = 0.0);

/// The checkpoint file `path` and the `count` - 1 checkpoints before it in its folder (by
/// update: nn::CheckpointFilesIn), newest first. Throws std::runtime_error when `path` is not
/// one of the folder's checkpoint files or fewer than `count` - 1 come before it, and
/// std::invalid_argument for count < 1.
std::vector<std::string> EnsembleFiles(const std::string& path, int count);

/// Scores the mean action of the loaded checkpoints `ckpts`, read from `paths` (EnsemblePolicy;
/// continuous envs), as ScoreCheckpoint scores one: the record names paths[0] and has its
/// metadata. Throws std::runtime_error as PolicyNetwork for any of them, std::invalid_argument
/// for a discrete env, no checkpoint, or not as many paths as checkpoints. `tick` as in
/// ScorePolicy.
EvalRecord ScoreEnsemble(const std::vector<nn::Checkpoint>& ckpts,
                         const std::vector<std::string>& paths, const std::string& env_id,
                         int episodes, uint64_t first_seed, double gamma = kDefaultGamma,
                         const Tick& tick = {});

/// The checkpoint whose parameters are the mean of the loaded checkpoints' `ckpts`, read from
/// `paths` (their weights averaged, as stochastic weight averaging averages the weights along
/// one run): the architecture and metadata of ckpts[0] (EnsembleFiles' newest), its note after
/// a line naming the members' updates. Throws std::invalid_argument for no checkpoint or not as
/// many paths as checkpoints, and std::runtime_error naming the path of a member of another
/// architecture or run, or with another parameter count. Scored with ScoreCheckpoint under
/// paths[0], as one checkpoint.
nn::Checkpoint AverageCheckpoints(const std::vector<nn::Checkpoint>& ckpts,
                                  const std::vector<std::string>& paths);

/// Loads the checkpoint files `paths` and scores their mean action (ScoreEnsemble). Throws
/// std::runtime_error as ScoreCheckpointFile for any of the files, std::invalid_argument as
/// ScoreEnsemble.
EvalRecord ScoreEnsembleFiles(const std::vector<std::string>& paths, const std::string& env_id,
                              int episodes, uint64_t first_seed, double gamma = kDefaultGamma);

}  // namespace rl::evaluator
