// A LunarLanderContinuous actor that always takes the same action: the ensembles' tests know
// what the mean action of several such actors does.
#pragma once

#include <cstdint>
#include <random>
#include <vector>

#include "nn/checkpoint.h"
#include "nn/sequential.h"

namespace rl::evaluator::testing {

inline constexpr char kLander[] = "LunarLanderContinuous-v3";

// A LunarLanderContinuous actor whose action is always (main, side), at update `update` (2
// env steps an update) of run `run_id`.
inline nn::Checkpoint ConstantLanderCheckpoint(int64_t update, float main, float side,
                                               uint64_t run_id = 0) {
  std::mt19937 rng(1);
  nn::Sequential actor = nn::MakeMlp(8, {4}, 2, &rng);
  std::vector<float> flat(static_cast<size_t>(actor.NumParams()), 0.0f);
  flat[flat.size() - 2] = main;
  flat[flat.size() - 1] = side;
  actor.SetFlat(flat.data(), flat.size());
  nn::Checkpoint ckpt;
  ckpt.architecture = actor.Architecture();
  actor.GetFlat(&ckpt.params);
  ckpt.meta.update = update;
  ckpt.meta.env_steps = 2 * update;
  ckpt.meta.run_id = run_id;
  return ckpt;
}

}  // namespace rl::evaluator::testing
