// An evaluation record with plausible numbers, for the tests of the history and the report.
#pragma once

#include <cstdint>
#include <string>

#include "evaluator/eval_history.h"

namespace rl::evaluator::testing {

inline EvalRecord SampleRecord(const std::string& name, int64_t update, double mean) {
  EvalRecord r;
  r.checkpoint = name;
  r.update = update;
  r.env_steps = update * 4;
  r.wall_seconds = static_cast<double>(update) / 30.0;
  r.mean = mean;
  r.std = mean / 7.0;
  r.min = mean / 2;
  r.max = mean * 1.5;
  r.episodes = 100;
  r.eval_seconds = 0.1 + static_cast<double>(update) * 1e-6;
  return r;
}

}  // namespace rl::evaluator::testing
