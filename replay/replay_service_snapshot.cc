// ReplayService's snapshots: what a restarted replay needs to serve as before (see
// replay_service.h).
#include <cstdint>
#include <memory>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "replay/replay_service.h"

namespace rl::replay {
namespace {

// Largest count a snapshot may hold (far from overflow; 2^62 is ages of any run).
constexpr int64_t kMaxCount = int64_t{1} << 62;

}  // namespace

std::string ReplayService::Summary() const {
  std::string s = "size " + std::to_string(size()) + " of " + std::to_string(table_->capacity()) +
                  ", inserts " + std::to_string(total_inserts()) + ", samples " +
                  std::to_string(total_samples());
  if (table_->frame_capacity() > 0) s += ", frames " + std::to_string(table_->total_frames());
  return s;
}

std::string ReplayService::SaveSnapshot(StateStream* out) const {
  out->PutInt("run_id", bus_.config().run_id);
  // The table's kind names it and prefixes its sections: "flat." or "pixels.".
  const std::string kind = TableKindName(table_->kind());
  out->PutText("table", kind);
  const int64_t limiter[] = {limiter_.inserts(), limiter_.samples()};
  out->PutInts("limiter", limiter);
  std::ostringstream rng;
  rng << rng_;
  out->PutText("rng", rng.str());
  const int64_t counters[] = {counters_.batches_refused,    counters_.requests_refused,
                              counters_.requests_dropped,   counters_.requests_answered,
                              counters_.priorities_applied, counters_.priorities_stale};
  out->PutInts("counters", counters);
  std::vector<int64_t> actors;
  for (const auto& [id, n] : actor_inserts_) actors.insert(actors.end(), {int64_t{id}, n});
  out->PutInts("actor_inserts", actors);
  table_->Save(kind + ".", out);
  // The last message heard from each sender, so that a restarted replay refuses recorded traffic
  // that this state already holds (common/lcm_bus.h).
  out->PutText("bus_positions", bus_.SavePositions());
  return Summary();
}

void ReplayService::Restore(const StateView& in) {
  const int64_t run_id = in.Int("run_id");
  if (run_id != bus_.config().run_id) {
    throw std::runtime_error("a snapshot of run " + std::to_string(run_id) + ", this is run " +
                             std::to_string(bus_.config().run_id));
  }
  RestoreTable(in);
  int64_t limiter[2] = {};
  in.Copy<int64_t>("limiter", limiter);
  if (limiter[0] > kMaxCount || limiter[1] > kMaxCount) {
    throw std::runtime_error("section 'limiter' holds counts beyond 2^62");
  }
  limiter_.Restore(limiter[0], limiter[1]);
  std::istringstream rng(in.Text("rng"));
  rng >> rng_;
  if (rng.fail()) throw std::runtime_error("section 'rng' is not a generator's state");
  int64_t counters[6] = {};
  in.Copy<int64_t>("counters", counters);
  for (const int64_t n : counters) {
    if (n < 0 || n > kMaxCount) throw std::runtime_error("section 'counters' holds a bad count");
  }
  counters_ =
      ServiceCounters{counters[0], counters[1], counters[2], counters[3], counters[4], counters[5]};
  // The ids a running service stores (below max_actors), as it saved them.
  const std::vector<int64_t> actors = in.Ints("actor_inserts", 2 * int64_t{kMaxActorsLimit});
  if (actors.size() % 2 != 0) throw std::runtime_error("section 'actor_inserts' is not pairs");
  actor_inserts_.clear();
  for (size_t k = 0; k < actors.size(); k += 2) {
    if (actors[k] < 0 || actors[k] >= options_.max_actors) {
      throw std::runtime_error("section 'actor_inserts' holds actor id " +
                               std::to_string(actors[k]) + ", this replay stores ids below " +
                               std::to_string(options_.max_actors) + " (max-actors)");
    }
    if (actors[k + 1] < 0 || actors[k + 1] > kMaxCount) {
      throw std::runtime_error("section 'actor_inserts' holds a bad count");
    }
    actor_inserts_[static_cast<int32_t>(actors[k])] = actors[k + 1];
  }
  insert_allowed_ = limiter_.CanInsert(options_.insert_unit);
  low_credit_ = limiter_.InsertCredit();
  // Snapshots written before the bus kept positions have none.
  if (in.Has("bus_positions")) bus_.LoadPositions(in.Text("bus_positions"));
}

void ReplayService::RestoreTable(const StateView& in) {
  const std::string name = in.Text("table");
  // Replays that chose their table at the first batch wrote "empty" (with an empty flat table's
  // sections) before any: the fresh table stays as it is.
  if (name == "empty") return;
  std::optional<TableKind> kind;
  for (const TableKind k : {TableKind::kFlat, TableKind::kPixels}) {
    if (name == TableKindName(k)) kind = k;
  }
  if (!kind) throw std::runtime_error("unknown table kind '" + name + "'");
  if (*kind != table_->kind()) {
    if (options_.kind) {
      throw std::runtime_error("the snapshot's table holds " + name + " transitions, this env's " +
                               TableKindName(table_->kind()));
    }
    table_ = MakeTable(*kind);
  }
  table_->Restore(name + ".", in);
}

void ReplayService::CheckFresh() const {
  if (!table_->unused() || total_samples() != 0 || !pending_.empty() || limiter_.inserts() != 0) {
    throw std::logic_error("a snapshot can only be restored into a fresh replay service");
  }
}

std::string ReplayService::RestoreSnapshot(std::string_view bytes) {
  CheckFresh();
  try {
    Restore(StateView::Parse(bytes, kSnapshotKind));
  } catch (const std::exception& e) {
    throw std::runtime_error(e.what());
  }
  return Summary();
}

std::string ReplayService::LoadSnapshot(const std::string& path) {
  CheckFresh();
  const StateView view = StateView::Map(path, kSnapshotKind);
  try {
    Restore(view);
  } catch (const std::exception& e) {
    throw std::runtime_error("state " + path + " refused: " + e.what());
  }
  return Summary();
}

}  // namespace rl::replay
