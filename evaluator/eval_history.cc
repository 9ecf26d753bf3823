#include "evaluator/eval_history.h"

#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <stdexcept>
#include <utility>

#include "evaluator/json_line.h"

namespace rl::evaluator {

std::string ToJson(const EvalRecord& r) {
  nlohmann::ordered_json j;
  j["checkpoint"] = r.checkpoint;
  j["update"] = r.update;
  j["env_steps"] = r.env_steps;
  j["wall_seconds"] = r.wall_seconds;
  j["mean"] = r.mean;
  j["std"] = r.std;
  j["min"] = r.min;
  j["max"] = r.max;
  j["episodes"] = r.episodes;
  j["eval_seconds"] = r.eval_seconds;
  if (r.value_steps > 0) {
    j["value_steps"] = r.value_steps;
    j["value_estimate"] = r.value_estimate;
    j["value_return"] = r.value_return;
    j["value_correlation"] = r.value_correlation ? nlohmann::ordered_json(*r.value_correlation)
                                                 : nlohmann::ordered_json(nullptr);
  }
  if (r.second_episodes > 0) {
    j["second_mean"] = r.second_mean;
    j["second_std"] = r.second_std;
    j["second_episodes"] = r.second_episodes;
  }
  if (r.ensemble_size > 0) {
    j["ensemble_size"] = r.ensemble_size;
    j["ensemble_by"] = r.ensemble_by;
    j["ensemble_from"] = r.ensemble_from;
    j["ensemble_mean"] = r.ensemble_mean;
    j["ensemble_std"] = r.ensemble_std;
    j["ensemble_min"] = r.ensemble_min;
    j["ensemble_max"] = r.ensemble_max;
    j["ensemble_returns"] = r.ensemble_returns;
  }
  if (!r.returns.empty()) j["returns"] = r.returns;
  if (!r.steps.empty()) j["steps"] = r.steps;
  if (!r.action_mean.empty()) j["action_mean"] = r.action_mean;
  return JsonLine(j);
}

bool ParseJson(const std::string& line, EvalRecord* record) {
  const std::optional<nlohmann::json> j = ParseJsonLine(line);
  if (!j) return false;
  const std::optional<std::string> name = JsonStringAt(*j, "checkpoint");
  const std::optional<int64_t> update = JsonIntegerAt(*j, "update");
  const std::optional<double> mean = JsonNumberAt(*j, "mean");
  if (!name || !update || !mean) return false;
  const auto number = [&j](const char* key, double otherwise) {
    return JsonNumberAt(*j, key).value_or(otherwise);
  };
  const auto integer = [&j](const char* key) { return JsonIntegerAt(*j, key).value_or(0); };
  EvalRecord r;
  r.checkpoint = *name;
  r.update = *update;
  r.mean = *mean;
  r.env_steps = integer("env_steps");
  r.wall_seconds = number("wall_seconds", 0);
  r.std = number("std", 0);
  r.min = number("min", r.mean);
  r.max = number("max", r.mean);
  r.episodes = static_cast<int>(integer("episodes"));
  r.eval_seconds = number("eval_seconds", 0);
  r.value_steps = integer("value_steps");
  if (r.value_steps > 0) {
    r.value_estimate = number("value_estimate", 0);
    r.value_return = number("value_return", 0);
    const double c = number("value_correlation", std::nan(""));
    if (std::isfinite(c)) r.value_correlation = c;
  }
  r.second_episodes = static_cast<int>(integer("second_episodes"));
  if (r.second_episodes > 0) {
    r.second_mean = number("second_mean", 0);
    r.second_std = number("second_std", 0);
  }
  r.ensemble_size = static_cast<int>(integer("ensemble_size"));
  const std::optional<double> ensemble_mean = JsonNumberAt(*j, "ensemble_mean");
  if (r.ensemble_size > 0 && ensemble_mean) {
    // Lines from before averages of weights were scored are ensembles of actions.
    r.ensemble_by = JsonStringAt(*j, "ensemble_by").value_or("actions");
    if (r.ensemble_by != "weights") r.ensemble_by = "actions";
    r.ensemble_from = integer("ensemble_from");
    r.ensemble_mean = *ensemble_mean;
    r.ensemble_std = number("ensemble_std", 0);
    r.ensemble_min = number("ensemble_min", r.ensemble_mean);
    r.ensemble_max = number("ensemble_max", r.ensemble_mean);
    r.ensemble_returns = JsonNumbersAt(*j, "ensemble_returns").value_or(std::vector<double>{});
  } else {
    r.ensemble_size = 0;
  }
  r.returns = JsonNumbersAt(*j, "returns").value_or(std::vector<double>{});
  for (double steps : JsonNumbersAt(*j, "steps").value_or(std::vector<double>{})) {
    if (!(steps >= 0 && steps <= 1e9 && steps == std::floor(steps))) {
      r.steps.clear();
      break;
    }
    r.steps.push_back(static_cast<int>(steps));
  }
  r.action_mean = JsonNumbersAt(*j, "action_mean").value_or(std::vector<double>{});
  *record = std::move(r);
  return true;
}

void AppendJsonLine(const std::string& path, const EvalRecord& record) {
  const std::string line = ToJson(record) + "\n";
  std::FILE* f = std::fopen(path.c_str(), "a");
  if (f == nullptr) {
    throw std::runtime_error("cannot open '" + path + "': " + std::strerror(errno));
  }
  const bool written = std::fwrite(line.data(), 1, line.size(), f) == line.size();
  const bool flushed = written && std::fflush(f) == 0 && ::fsync(fileno(f)) == 0;
  const int saved_errno = errno;
  std::fclose(f);
  if (!flushed) {
    throw std::runtime_error("cannot append to '" + path + "': " + std::strerror(saved_errno));
  }
}

std::vector<EvalRecord> LoadJsonLines(const std::string& path, int* skipped_lines) {
  std::vector<EvalRecord> records;
  int skipped = 0;
  std::ifstream in(path);
  std::string line;
  while (in && std::getline(in, line)) {
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    EvalRecord r;
    if (ParseJson(line, &r)) {
      records.push_back(std::move(r));
    } else {
      ++skipped;
    }
  }
  if (skipped_lines != nullptr) *skipped_lines = skipped;
  return records;
}

EvalHistory::EvalHistory(std::string jsonl_path) : path_(std::move(jsonl_path)) {
  records_ = LoadJsonLines(path_, &skipped_lines_);
}

void EvalHistory::Add(const EvalRecord& record) {
  records_.push_back(record);
  if (!path_.empty()) AppendJsonLine(path_, record);
}

bool EvalHistory::Contains(const std::string& checkpoint, int64_t update) const {
  return std::any_of(records_.begin(), records_.end(), [&](const EvalRecord& r) {
    return r.checkpoint == checkpoint && r.update == update;
  });
}

const EvalRecord* EvalHistory::best() const {
  const EvalRecord* b = nullptr;
  for (const EvalRecord& r : records_) {
    if (b == nullptr || r.mean > b->mean) b = &r;
  }
  return b;
}

}  // namespace rl::evaluator
