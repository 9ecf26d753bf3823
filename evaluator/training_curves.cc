#include "evaluator/training_curves.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <optional>

#include "evaluator/json_line.h"

namespace rl::evaluator {
namespace {

// The values of one row (one t) of metrics.jsonl, combined across the actors.
struct Row {
  double return_sum = 0, exploration_sum = 0, steps_per_second = 0;
  int actors = 0;
  std::optional<double> loss, mean_q, updates_per_second, replay_size;
};

}  // namespace

std::vector<TrainingSeries> LoadTrainingSeries(const std::string& path) {
  std::ifstream in(path);
  std::map<double, Row> rows;  // by t
  for (std::string line; std::getline(in, line);) {
    const std::optional<nlohmann::json> obj = ParseJsonLine(line);
    if (!obj) continue;
    const std::optional<double> t = JsonNumberAt(*obj, "t");
    const std::optional<std::string> role = JsonStringAt(*obj, "role");
    if (!t || !std::isfinite(*t) || !role) continue;
    Row& row = rows[*t];
    const std::string& who = *role;
    const auto get = [&obj](const char* key) { return JsonNumberAt(*obj, key); };
    if (who.rfind("actor-", 0) == 0) {
      const auto ret = get("mean_return"), exploration = get("exploration"),
                 speed = get("steps_per_second");
      if (!ret || !exploration || !speed) continue;
      row.return_sum += *ret;
      row.exploration_sum += *exploration;
      row.steps_per_second += *speed;
      ++row.actors;
    } else if (who == "learner") {
      row.loss = get("loss");
      row.mean_q = get("mean_q");
      row.updates_per_second = get("updates_per_second");
    } else if (who == "replay") {
      row.replay_size = get("size");
    }
  }

  std::vector<TrainingSeries> series = {
      {"train_return.svg", "Training return (mean of the actors' last 100 episodes)", "return", {}},
      {"train_exploration.svg",
       "Exploration (actors' mean epsilon or noise scale)",
       "exploration",
       {}},
      {"train_env_steps.svg", "Environment steps per second (all actors)", "steps/s", {}},
      {"train_loss.svg", "Learner loss", "loss", {}},
      {"train_mean_q.svg", "Mean Q of the trained batches", "mean Q", {}},
      {"train_updates.svg", "Learner updates per second", "updates/s", {}},
      {"train_replay_size.svg", "Replay size", "transitions", {}},
  };
  const auto add = [&series](size_t i, double t, std::optional<double> v) {
    if (v && std::isfinite(*v)) series[i].points.push_back({t, *v, 0.0});
  };
  for (const auto& [t, row] : rows) {
    if (row.actors > 0) {
      add(0, t, row.return_sum / row.actors);
      add(1, t, row.exploration_sum / row.actors);
      add(2, t, row.steps_per_second);
    }
    add(3, t, row.loss);
    add(4, t, row.mean_q);
    add(5, t, row.updates_per_second);
    add(6, t, row.replay_size);
  }
  std::vector<TrainingSeries> kept;
  for (TrainingSeries& s : series) {
    if (!s.points.empty()) kept.push_back(std::move(s));
  }
  return kept;
}

ActorEpisodes LoadActorEpisodes(const std::string& path) {
  std::ifstream in(path);
  std::map<std::string, std::pair<int64_t, int64_t>> by_role;  // {earlier lives, this life}
  const auto total = [&by_role] {
    int64_t sum = 0;
    for (const auto& [role, counts] : by_role) sum += counts.first + counts.second;
    return sum;
  };
  ActorEpisodes result;
  for (std::string line; std::getline(in, line);) {
    const std::optional<nlohmann::json> obj = ParseJsonLine(line);
    if (!obj) continue;
    const std::optional<std::string> role = JsonStringAt(*obj, "role");
    if (!role) continue;
    if (role->rfind("actor-", 0) == 0) {
      const std::optional<int64_t> episodes = JsonIntegerAt(*obj, "episodes");
      if (!episodes) continue;
      auto& [earlier, current] = by_role[*role];
      if (*episodes < current) earlier += current;
      current = *episodes;
    } else if (*role == "learner") {
      const std::optional<int64_t> updates = JsonIntegerAt(*obj, "updates");
      if (updates && !by_role.empty()) result.by_update.push_back({*updates, total()});
    }
  }
  result.total = total();
  return result;
}

std::optional<int64_t> EpisodesAt(const std::vector<EpisodesAtUpdate>& points, int64_t update) {
  // Updates only grow within a run (a resumed learner continues its count).
  const auto it = std::find_if(points.begin(), points.end(),
                               [update](const EpisodesAtUpdate& p) { return p.updates >= update; });
  if (it == points.end()) return std::nullopt;
  return it->episodes;
}

}  // namespace rl::evaluator
