// ReplayService's snapshots: what a restarted replay needs to serve as before (see
// replay_service.h).
#include <cstdint>
#include <memory>
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

// The pixel table as InsertPixels() creates it at a run's first pixel batch.
std::unique_ptr<PixelTable> ReplayService::MakePixelTable() const {
  PixelTableOptions options;
  options.capacity = options_.table.capacity;
  options.frame_capacity = options_.frame_capacity;
  options.action_width = options_.table.action_width;
  return std::make_unique<PixelTable>(options, MakeSampler());
}

std::string ReplayService::Summary() const {
  std::string s = "size " + std::to_string(size()) + " of " + std::to_string(table_.capacity()) +
                  ", inserts " + std::to_string(total_inserts()) + ", samples " +
                  std::to_string(total_samples());
  if (pixels_ != nullptr) s += ", frames " + std::to_string(pixels_->total_frames());
  return s;
}

std::string ReplayService::SaveSnapshot(StateStream* out) const {
  out->PutInt("run_id", bus_.config().run_id);
  out->PutText("table", pixels_ != nullptr           ? "pixels"
                        : table_.total_inserts() > 0 ? "flat"
                                                     : "empty");
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
  if (pixels_ != nullptr) {
    pixels_->Save("pixels.", out);
  } else {
    table_.Save("flat.", out);
  }
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
  const std::string table = in.Text("table");
  if (table == "pixels") {
    pixels_ = MakePixelTable();
    pixels_->Restore("pixels.", in);
  } else if (table == "flat" || table == "empty") {
    table_.Restore("flat.", in);
  } else {
    throw std::runtime_error("unknown table kind '" + table + "'");
  }
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

void ReplayService::CheckFresh() const {
  if (total_inserts() != 0 || total_samples() != 0 || !pending_.empty() ||
      limiter_.inserts() != 0 || pixels_ != nullptr) {
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
