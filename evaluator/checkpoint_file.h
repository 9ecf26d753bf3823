// A checkpoint file as the evaluator uses it: loaded into a policy network that fits the env,
// and scored (scorer.h) into an EvalRecord.
#pragma once

#include <cstdint>
#include <string>

#include "evaluator/eval_history.h"
#include "evaluator/progress.h"
#include "evaluator/scorer.h"
#include "nn/checkpoint.h"
#include "nn/sequential.h"

namespace rl::evaluator {

/// Loads a checkpoint file and builds its network; fills *meta when not null. Throws
/// std::runtime_error with the reason when the file is refused (see ScoreCheckpointFile).
nn::Sequential LoadPolicyNetwork(const std::string& path, const std::string& env_id,
                                 nn::CheckpointMeta* meta = nullptr);

/// Loads a checkpoint file, builds its network and scores it on `env_id` (see ScorePolicy), with
/// its value estimates against the returns (discount gamma).
/// The record's update, env_steps and wall_seconds come from the file's metadata. Throws
/// std::runtime_error with the reason when the file is refused: it does not load (missing,
/// truncated, corrupted, foreign), its architecture does not build, its parameters do not fit
/// the architecture, or the network does not fit the env. `after_episode` as in ScorePolicy.
EvalRecord ScoreCheckpointFile(const std::string& path, const std::string& env_id, int episodes,
                               double epsilon, uint64_t first_seed, double gamma = kDefaultGamma,
                               const Tick& after_episode = {});

}  // namespace rl::evaluator
