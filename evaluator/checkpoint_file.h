// A checkpoint as the evaluator uses it: built into a policy network that fits the env, and
// scored (scorer.h) into an EvalRecord. From a file given by hand (read wherever it is) or from a
// checkpoint already read (an announced one: announced_checkpoint.h).
#pragma once

#include <cstdint>
#include <string>

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

}  // namespace rl::evaluator
