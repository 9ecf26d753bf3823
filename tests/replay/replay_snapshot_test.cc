// Snapshots of the replay: a restored service serves as the saved one did, a written file loads,
// and every bad file is refused with a clear error.
#include <algorithm>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <memory>
#include <random>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "common/channels.h"
#include "common/crc32.h"
#include "common/lcm_bus.h"
#include "common/message_examples.h"
#include "common/state_file.h"
#include "replay/replay_service.h"
#include "replay/snapshotter.h"
#include "tests/common/error_of.h"
#include "tests/common/temp_dir.h"

namespace rl::replay {
namespace {

namespace fs = std::filesystem;

constexpr int64_t kRunId = 42;

// Transitions first .. first + count - 1 of one actor, obs {v, v + 0.5, v + 1, v + 1.5},
// reward v, priority (v % 7) / 2 (0: none given).
rlmsg::transition_batch_t FlatBatch(int first, int count, int32_t actor = 0) {
  return examples::FlatTransitions(first, count, 4, 1, actor);
}

// Pixel frames first_frame .. first_frame + count of one actor (3 x 2 bytes, every byte of frame
// f equal to f + actor), and transitions t naming frames {t - 1, t} and {t, t + 1}.
rlmsg::transition_batch_t PixelBatch(int first_frame, int count, int32_t actor) {
  return examples::PixelTransitions(first_frame, count, 3, 2, actor);
}

ReplayServiceOptions Options(bool prioritized, int64_t capacity = 200) {
  ReplayServiceOptions o;
  o.table.capacity = capacity;
  o.frame_capacity = 150;
  o.limiter.samples_per_insert = 4;
  o.limiter.min_size_to_sample = 20;
  o.limiter.error_buffer = 400;
  o.prioritized = prioritized;
  o.beta_anneal_samples = 5000;
  o.seed = 7;
  return o;
}

// A replay service on its own in-process bus, with a test peer publishing to it.
class Replica {
 public:
  explicit Replica(const ReplayServiceOptions& options, int64_t run_id = kRunId)
      : bus_(InProcessBusConfig(run_id, "replay")), run_id_(run_id) {
    bus_.Subscribe<rlmsg::sample_batch_t>(
        channels::kSamples, [this](const rlmsg::sample_batch_t& m) { replies_.push_back(m); },
        Port::kSamples);
    service_ = std::make_unique<ReplayService>(&bus_, options);
  }

  template <class Msg>
  void Publish(const std::string& channel, Msg m, const std::string& sender) {
    m.header.run_id = run_id_;
    m.header.sender = sender;
    m.header.seq = seq_[sender]++;
    m.header.utime = WallMicros();
    m.header.incarnation = incarnation_;
    std::vector<uint8_t> bytes(static_cast<size_t>(m.getEncodedSize()));
    ASSERT_EQ(m.encode(bytes.data(), 0, static_cast<int>(bytes.size())),
              static_cast<int>(bytes.size()));
    ASSERT_TRUE(bus_.PublishRaw(channel, bytes.data(), bytes.size()));
    bus_.Handle(0);
  }
  // Asks for a batch and returns the reply (empty when there is none).
  rlmsg::sample_batch_t Sample(int64_t id, int batch_size, bool expect_reply = true) {
    rlmsg::sample_request_t r{};
    r.request_id = id;
    r.batch_size = batch_size;
    Publish(channels::kSampleRequest, r, "learner-0");
    service_->Serve();
    bus_.Handle(0);
    EXPECT_TRUE(!expect_reply || !replies_.empty()) << "no reply to request " << id;
    if (replies_.empty()) return {};
    rlmsg::sample_batch_t reply = replies_.back();
    replies_.clear();
    return reply;
  }
  void Prioritize(const rlmsg::sample_batch_t& reply) {
    rlmsg::priority_update_t u{};
    u.count = reply.count;
    u.index = reply.index;
    for (int i = 0; i < reply.count; ++i) {
      u.priority.push_back(static_cast<float>(reply.index[static_cast<size_t>(i)] % 5) + 0.25f);
    }
    Publish(channels::kPriorities, u, "learner-0");
  }
  std::string Snapshot() const {
    StateStream out(ReplayService::kSnapshotKind);
    service_->SaveSnapshot(&out);
    return out.Serialize();
  }
  ReplayService& service() { return *service_; }

 private:
  // The test peer's senders start anew with each replica, as restarted processes do: a later
  // incarnation (a restored replica refuses what the saved one's peer had sent).
  static int64_t NewIncarnation() {
    static int64_t last = 0;
    return last = std::max(WallMicros(), last + 1);
  }

  Bus bus_;
  int64_t run_id_;
  int64_t incarnation_ = NewIncarnation();
  std::unique_ptr<ReplayService> service_;
  std::map<std::string, int64_t> seq_;
  std::vector<rlmsg::sample_batch_t> replies_;
};

// Fills a flat replay past its capacity, samples from it and gives it priorities.
void FillFlat(Replica* r) {
  for (int k = 0; k < 12; ++k) {
    r->Publish(channels::kTransitions, FlatBatch(25 * k, 25, k % 3),
               "actor-" + std::to_string(k % 3));
  }
  for (int k = 0; k < 5; ++k) r->Prioritize(r->Sample(k, 32));
}

void ExpectSameReplies(Replica* a, Replica* b, int rounds) {
  for (int k = 0; k < rounds; ++k) {
    const rlmsg::sample_batch_t x = a->Sample(100 + k, 32);
    const rlmsg::sample_batch_t y = b->Sample(100 + k, 32);
    EXPECT_EQ(x.index, y.index) << "round " << k;
    EXPECT_EQ(x.weight, y.weight) << "round " << k;
    EXPECT_EQ(x.obs, y.obs) << "round " << k;
    EXPECT_EQ(x.next_obs, y.next_obs) << "round " << k;
    EXPECT_EQ(x.obs_pixels, y.obs_pixels) << "round " << k;
    EXPECT_EQ(x.next_obs_pixels, y.next_obs_pixels) << "round " << k;
    EXPECT_EQ(x.action, y.action) << "round " << k;
    EXPECT_EQ(x.reward, y.reward) << "round " << k;
    EXPECT_EQ(x.replay_size, y.replay_size) << "round " << k;
    a->Prioritize(x);
    b->Prioritize(y);
  }
}

void ExpectSameState(ReplayService& a, ReplayService& b) {
  EXPECT_EQ(a.size(), b.size());
  EXPECT_EQ(a.total_inserts(), b.total_inserts());
  EXPECT_EQ(a.total_samples(), b.total_samples());
  EXPECT_EQ(a.limiter().inserts(), b.limiter().inserts());
  EXPECT_EQ(a.limiter().samples(), b.limiter().samples());
  EXPECT_EQ(a.beta(), b.beta());
  EXPECT_EQ(a.counters().priorities_applied, b.counters().priorities_applied);
  EXPECT_EQ(a.counters().requests_answered, b.counters().requests_answered);
  EXPECT_EQ(a.insert_allowed(), b.insert_allowed());
}

class ReplaySnapshotTest : public TempDirTest {
 protected:
  std::string Write(const std::string& name, const std::string& bytes) const {
    std::string path = (dir_ / name).string();
    std::ofstream(path, std::ios::binary) << bytes;
    return path;
  }
  // The error of loading `bytes` (as a file) into a fresh replay of `options`.
  std::string LoadError(const std::string& bytes, const ReplayServiceOptions& options,
                        int64_t run_id = kRunId) {
    const std::string path = Write("bad.bin", bytes);
    Replica fresh(options, run_id);
    std::string error = ErrorOf([&] { fresh.service().LoadSnapshot(path); });
    EXPECT_NE(error.find(path), std::string::npos) << "the error does not name the file: " << error;
    return error;
  }
};

TEST_F(ReplaySnapshotTest, ARestoredPrioritizedFlatReplaySamplesAsTheSavedOne) {
  Replica saved(Options(/*prioritized=*/true));
  FillFlat(&saved);
  Replica restored(Options(true));
  const std::string summary = restored.service().RestoreSnapshot(saved.Snapshot());
  EXPECT_EQ(summary, "size 200 of 200, inserts 300, samples 160");
  ExpectSameState(saved.service(), restored.service());
  ExpectSameReplies(&saved, &restored, 6);
  // And both go on alike with new transitions.
  saved.Publish(channels::kTransitions, FlatBatch(300, 30, 4), "actor-4");
  restored.Publish(channels::kTransitions, FlatBatch(300, 30, 4), "actor-4");
  ExpectSameReplies(&saved, &restored, 3);
  ExpectSameState(saved.service(), restored.service());
}

TEST_F(ReplaySnapshotTest, ARestoredUniformFlatReplaySamplesAsTheSavedOne) {
  Replica saved(Options(false));
  FillFlat(&saved);
  Replica restored(Options(false));
  restored.service().RestoreSnapshot(saved.Snapshot());
  ExpectSameState(saved.service(), restored.service());
  ExpectSameReplies(&saved, &restored, 5);
}

TEST_F(ReplaySnapshotTest, ARestoredPixelReplayKeepsFramesAndActorWindows) {
  Replica saved(Options(true));
  // Two actors; the frame ring (150) wraps, so some transitions are stale.
  for (int k = 0; k < 4; ++k) {
    saved.Publish(channels::kTransitions, PixelBatch(40 * k, 40, 0), "actor-0");
    saved.Publish(channels::kTransitions, PixelBatch(40 * k, 20, 1), "actor-1");
  }
  for (int k = 0; k < 3; ++k) saved.Prioritize(saved.Sample(k, 16));
  Replica restored(Options(true));
  const std::string summary = restored.service().RestoreSnapshot(saved.Snapshot());
  EXPECT_NE(summary.find("frames"), std::string::npos) << summary;
  ExpectSameState(saved.service(), restored.service());
  ASSERT_EQ(restored.service().table().kind(), TableKind::kPixels);
  EXPECT_EQ(restored.service().table().total_frames(), saved.service().table().total_frames());
  EXPECT_EQ(restored.service().table().stale_draws(), saved.service().table().stale_draws());
  ExpectSameReplies(&saved, &restored, 4);
  // A next batch that names a frame of the previous one resolves through the restored window.
  rlmsg::transition_batch_t next = PixelBatch(160, 10, 0);
  next.obs_frames[0] = 159;
  saved.Publish(channels::kTransitions, next, "actor-0");
  restored.Publish(channels::kTransitions, next, "actor-0");
  EXPECT_EQ(restored.service().table().transitions_missing_frames(),
            saved.service().table().transitions_missing_frames());
  EXPECT_EQ(restored.service().total_inserts(), saved.service().total_inserts());
  ExpectSameReplies(&saved, &restored, 3);
}

TEST_F(ReplaySnapshotTest, AnEmptyReplayRoundTrips) {
  Replica saved(Options(false));
  Replica restored(Options(false));
  EXPECT_EQ(restored.service().RestoreSnapshot(saved.Snapshot()),
            "size 0 of 200, inserts 0, samples 0");
  restored.Publish(channels::kTransitions, FlatBatch(0, 30), "actor-0");
  EXPECT_EQ(restored.service().size(), 30);
}

// The options of a replay whose table kind the env's spec gave.
ReplayServiceOptions OptionsOfKind(TableKind kind) {
  ReplayServiceOptions o = Options(false);
  o.kind = kind;
  return o;
}

TEST_F(ReplaySnapshotTest, LoadsAnEmptyReplayOfTheFormerFormatIntoEitherKind) {
  // Replays that chose their table at the first batch saved one that had stored nothing as
  // table "empty", with an empty flat table's sections: the same file with that one text.
  Replica saved(Options(false));
  std::string bytes = saved.Snapshot();
  const uint64_t flat_length = 4;
  const uint64_t empty_length = 5;
  const std::string table =
      std::string("table") + std::string(reinterpret_cast<const char*>(&flat_length), 8) + "flat";
  const size_t at = bytes.find(table);
  ASSERT_NE(at, std::string::npos);
  bytes.replace(at, table.size(),
                std::string("table") +
                    std::string(reinterpret_cast<const char*>(&empty_length), 8) + "empty");
  const uint32_t crc = Crc32(bytes.data(), bytes.size() - 4);
  std::memcpy(bytes.data() + bytes.size() - 4, &crc, 4);

  Replica flat(OptionsOfKind(TableKind::kFlat));
  EXPECT_EQ(flat.service().RestoreSnapshot(bytes), "size 0 of 200, inserts 0, samples 0");
  flat.Publish(channels::kTransitions, FlatBatch(0, 30), "actor-0");
  EXPECT_EQ(flat.service().size(), 30);
  Replica pixels(OptionsOfKind(TableKind::kPixels));
  EXPECT_EQ(pixels.service().RestoreSnapshot(bytes),
            "size 0 of 200, inserts 0, samples 0, frames 0");
  pixels.Publish(channels::kTransitions, PixelBatch(0, 30, 0), "actor-0");
  EXPECT_EQ(pixels.service().size(), 30);
}

TEST_F(ReplaySnapshotTest, RefusesATableOfTheOtherKindThanTheEnvs) {
  Replica flat(OptionsOfKind(TableKind::kFlat));
  flat.Publish(channels::kTransitions, FlatBatch(0, 30), "actor-0");
  EXPECT_NE(LoadError(flat.Snapshot(), OptionsOfKind(TableKind::kPixels))
                .find("the snapshot's table holds flat transitions, this env's pixels"),
            std::string::npos);
  Replica pixels(OptionsOfKind(TableKind::kPixels));
  pixels.Publish(channels::kTransitions, PixelBatch(0, 30, 0), "actor-0");
  EXPECT_NE(LoadError(pixels.Snapshot(), OptionsOfKind(TableKind::kFlat))
                .find("the snapshot's table holds pixels transitions, this env's flat"),
            std::string::npos);
  // Without a kind from the env, the snapshot's kind is taken.
  Replica any(Options(false));
  EXPECT_NE(any.service().RestoreSnapshot(pixels.Snapshot()).find("size 30"), std::string::npos);
  EXPECT_EQ(any.service().table().kind(), TableKind::kPixels);
}

TEST_F(ReplaySnapshotTest, RefusesTornFlippedForeignAndOtherRunFiles) {
  Replica saved(Options(true));
  FillFlat(&saved);
  const std::string bytes = saved.Snapshot();
  // Torn: cut anywhere.
  for (size_t n : {size_t{0}, size_t{5}, size_t{40}, bytes.size() / 2, bytes.size() - 1}) {
    const std::string error = LoadError(bytes.substr(0, n), Options(true));
    EXPECT_TRUE(error.find("checksum mismatch (torn or corrupted file)") != std::string::npos ||
                error.find("not a state file") != std::string::npos)
        << n << ": " << error;
  }
  // A flipped bit anywhere.
  for (size_t k : {size_t{3}, size_t{20}, bytes.size() / 3, bytes.size() - 2}) {
    std::string flipped = bytes;
    flipped[k] = static_cast<char>(flipped[k] ^ 0x04);
    const std::string error = LoadError(flipped, Options(true));
    EXPECT_TRUE(error.find("checksum mismatch") != std::string::npos ||
                error.find("not a state file") != std::string::npos)
        << k << ": " << error;
  }
  // Another file type: other magic, or a state file of another kind.
  EXPECT_NE(LoadError("\x89PNG\r\n\x1a\n and more bytes", Options(true)).find("not a state file"),
            std::string::npos);
  StateFile learner("learner dqn");
  learner.PutInt("updates", 5);
  EXPECT_NE(LoadError(learner.Serialize(), Options(true))
                .find("a state of 'learner dqn', expected 'replay snapshot'"),
            std::string::npos);
  // Another run.
  EXPECT_NE(LoadError(bytes, Options(true), 43).find("a snapshot of run 42, this is run 43"),
            std::string::npos);
}

TEST_F(ReplaySnapshotTest, RefusesATableOfAnotherShapeOrSampler) {
  Replica saved(Options(true));
  FillFlat(&saved);
  const std::string bytes = saved.Snapshot();
  EXPECT_NE(LoadError(bytes, Options(true, 300)).find("capacity 200, this replay's 300"),
            std::string::npos);
  EXPECT_NE(LoadError(bytes, Options(false)).find("sampler is prioritized, this replay's uniform"),
            std::string::npos);
  ReplayServiceOptions alpha = Options(true);
  alpha.alpha = 0.5;
  EXPECT_NE(LoadError(bytes, alpha).find("alpha"), std::string::npos);
  ReplayServiceOptions obs = Options(true);
  obs.table.obs_size = 8;
  EXPECT_NE(LoadError(bytes, obs).find("obs_size 4 and action width 1, this replay's 8"),
            std::string::npos);
  // A pixel snapshot into a replay of another frame capacity.
  Replica pixels(Options(false));
  pixels.Publish(channels::kTransitions, PixelBatch(0, 30, 0), "actor-0");
  ReplayServiceOptions frames = Options(false);
  frames.frame_capacity = 500;
  EXPECT_NE(LoadError(pixels.Snapshot(), frames)
                .find("capacity 200 and frame capacity 150, this replay's 200 and 500"),
            std::string::npos);
}

TEST_F(ReplaySnapshotTest, RefusesContentsThatAreNotAReplaysEvenWithAGoodChecksum) {
  Replica saved(Options(false));
  FillFlat(&saved);
  const std::string bytes = saved.Snapshot();
  // Sets value `index` of int64 section `name` to `to` and recomputes the checksum: a well
  // formed file whose contents are wrong.
  const auto forge = [&bytes](const std::string& name, size_t index, int64_t to) {
    std::string b = bytes;
    const size_t at = b.find(name) + name.size() + 8 + 8 * index;
    std::memcpy(b.data() + at, &to, 8);
    const uint32_t crc = Crc32(b.data(), b.size() - 4);
    std::memcpy(b.data() + b.size() - 4, &crc, 4);
    return b;
  };
  const auto error = [](const std::string& b) {
    Replica fresh(Options(false));
    return ErrorOf([&] { fresh.service().RestoreSnapshot(b); });
  };
  EXPECT_EQ(error(forge("flat.counts", 1, 300)), "");  // unchanged: loads
  EXPECT_NE(error(forge("flat.counts", 2, -1)).find("counters are inconsistent"),
            std::string::npos);
  EXPECT_NE(error(forge("flat.insert_number", 0, 12345)).find("insert numbers"), std::string::npos);
  EXPECT_NE(error(forge("flat.sampler.slots", 3, 9999)).find("slot out of range"),
            std::string::npos);
  EXPECT_NE(error(forge("limiter", 0, -5)).find("counts must be >= 0"), std::string::npos);
  EXPECT_NE(error(forge("run_id", 0, 7)).find("a snapshot of run 7"), std::string::npos);
}

// Random changes with the checksum made right again: each is refused with an error or loads a
// replay that then serves, inserts and samples without a crash (run under ASan and UBSan).
TEST_F(ReplaySnapshotTest, SurvivesMutatedSnapshotsWhoseChecksumIsRight) {
  Replica flat(Options(true));
  FillFlat(&flat);
  Replica pixels(Options(false));
  for (int k = 0; k < 3; ++k) {
    pixels.Publish(channels::kTransitions, PixelBatch(40 * k, 40, k % 2),
                   "actor-" + std::to_string(k % 2));
  }
  std::mt19937_64 rng(11);
  int loaded = 0;
  for (const bool pixel : {false, true}) {
    const std::string original = pixel ? pixels.Snapshot() : flat.Snapshot();
    for (int trial = 0; trial < 300; ++trial) {
      std::string b = original;
      // A few bytes set to random values, or an int64 set to a boundary value.
      const int changes = 1 + static_cast<int>(rng() % 3);
      for (int c = 0; c < changes; ++c) {
        const size_t at = 12 + rng() % (b.size() - 20);
        if (rng() % 2 == 0) {
          b[at] = static_cast<char>(rng());
        } else {
          const int64_t values[] = {-1,
                                    0,
                                    1,
                                    199,
                                    200,
                                    4096,
                                    std::numeric_limits<int64_t>::max(),
                                    std::numeric_limits<int64_t>::min()};
          std::memcpy(b.data() + at, &values[rng() % 8], 8);
        }
      }
      const uint32_t crc = Crc32(b.data(), b.size() - 4);
      std::memcpy(b.data() + b.size() - 4, &crc, 4);
      Replica fresh(Options(/*prioritized=*/!pixel));
      bool ok = true;
      try {
        fresh.service().RestoreSnapshot(b);
      } catch (const std::runtime_error&) {
        ok = false;
      }
      if (!ok) continue;
      ++loaded;
      fresh.Sample(1, 8, /*expect_reply=*/false);
      fresh.Publish(channels::kTransitions, FlatBatch(0, 5), "actor-9");
      fresh.Publish(channels::kTransitions, PixelBatch(500, 5, 3), "actor-3");
      fresh.Sample(2, 8, /*expect_reply=*/false);
    }
  }
  EXPECT_GT(loaded, 0);  // some changes (in frames, observations) are harmless
}

// A replay restored from a snapshot refuses the messages its saved self had taken (a recording
// played back after a restart), inside the freshness window too, and stores none of them.
TEST_F(ReplaySnapshotTest, ARestoredReplayRefusesTrafficItsSavedSelfHadTaken) {
  std::vector<std::vector<uint8_t>> recorded;
  Bus saved_bus(InProcessBusConfig(kRunId, "replay"));
  ReplayService saved(&saved_bus, Options(false));
  const int64_t now = WallMicros();
  for (int k = 0; k < 4; ++k) {
    rlmsg::transition_batch_t m = FlatBatch(25 * k, 25);
    m.header.run_id = kRunId;
    m.header.sender = "actor-0";
    m.header.seq = k;
    m.header.utime = now;
    m.header.incarnation = now - 1000;
    recorded.emplace_back(static_cast<size_t>(m.getEncodedSize()));
    ASSERT_EQ(m.encode(recorded.back().data(), 0, static_cast<int>(recorded.back().size())),
              static_cast<int>(recorded.back().size()));
    saved_bus.Deliver(channels::kTransitions, recorded.back().data(), recorded.back().size(), now);
  }
  ASSERT_EQ(saved.total_inserts(), 100);
  StateStream out(ReplayService::kSnapshotKind);
  saved.SaveSnapshot(&out);
  Bus restarted_bus(InProcessBusConfig(kRunId, "replay"));
  ReplayService restarted(&restarted_bus, Options(false));
  restarted.RestoreSnapshot(out.Serialize());
  for (const auto& bytes : recorded) {
    restarted_bus.Deliver(channels::kTransitions, bytes.data(), bytes.size(), now);
  }
  EXPECT_EQ(restarted.total_inserts(), 100);
  EXPECT_EQ(restarted_bus.counters().replayed, 4);
}

TEST_F(ReplaySnapshotTest, TheSnapshotterWritesFromAForkedChildAndTheFileLoads) {
  Replica saved(Options(true));
  FillFlat(&saved);
  SnapshotterOptions options;
  options.path = (dir_ / "replay-snapshot.bin").string();
  options.every_seconds = 10;
  // A temporary file of a writer that died earlier is removed.
  Write("replay-snapshot.bin.tmp.99999", "partial");
  ReplayService& service = saved.service();
  int64_t version = 1;
  Snapshotter snapshots(
      options, ReplayService::kSnapshotKind,
      [&service](StateStream* out) { return service.SaveSnapshot(out); },
      [&version] { return version; });
  EXPECT_FALSE(fs::exists(dir_ / "replay-snapshot.bin.tmp.99999"));
  // Due every 10 s from the first tick, and only when the state changed.
  EXPECT_FALSE(snapshots.Tick(100.0));
  EXPECT_FALSE(snapshots.Tick(109.0));
  EXPECT_FALSE(snapshots.Tick(110.0));  // due, but unchanged
  version = 2;
  EXPECT_FALSE(snapshots.Tick(115.0));
  EXPECT_TRUE(snapshots.Tick(120.0));
  EXPECT_TRUE(snapshots.running());
  EXPECT_FALSE(snapshots.StartNow());  // one child at a time
  snapshots.Wait();
  EXPECT_FALSE(snapshots.running());
  EXPECT_EQ(snapshots.stats().written, 1);
  EXPECT_EQ(snapshots.stats().failed, 0);
  EXPECT_GT(snapshots.stats().last_pause_seconds, 0.0);
  EXPECT_EQ(snapshots.stats().last_bytes, static_cast<int64_t>(fs::file_size(options.path)));
  // What the child wrote is the state at the fork.
  Replica restored(Options(true));
  restored.service().LoadSnapshot(options.path);
  ExpectSameState(saved.service(), restored.service());
  ExpectSameReplies(&saved, &restored, 2);
  // Finish() writes the last state in this process, when it changed.
  version = 3;
  EXPECT_TRUE(snapshots.Finish());
  EXPECT_EQ(snapshots.stats().written, 2);
  Replica last(Options(true));
  last.service().LoadSnapshot(options.path);
  ExpectSameState(saved.service(), last.service());
  // No temporary file is left.
  for (const auto& entry : fs::directory_iterator(dir_)) {
    EXPECT_EQ(entry.path().filename().string().find(".tmp."), std::string::npos) << entry.path();
  }
}

TEST_F(ReplaySnapshotTest, AFailedSnapshotIsCountedAndKeepsTheService) {
  Replica saved(Options(false));
  FillFlat(&saved);
  SnapshotterOptions options;
  options.path = (dir_ / "missing" / "replay-snapshot.bin").string();
  ReplayService& service = saved.service();
  Snapshotter snapshots(
      options, ReplayService::kSnapshotKind,
      [&service](StateStream* out) { return service.SaveSnapshot(out); }, [] { return 0; });
  EXPECT_TRUE(snapshots.StartNow());
  snapshots.Wait();
  EXPECT_EQ(snapshots.stats().written, 0);
  EXPECT_EQ(snapshots.stats().failed, 1);
  SnapshotterOptions bad;
  bad.every_seconds = 0;
  EXPECT_THROW(bad.Validate(), std::invalid_argument);
}

// Actor ids come from the network: a key holder may send any (2^31 - 1, or more distinct ones
// than a snapshot holds). Ids from max_actors on are refused and counted, so the per-actor
// counts stay bounded and the next snapshot loads; a replay told to take fewer ids refuses a
// snapshot that holds more, saying so.
TEST_F(ReplaySnapshotTest, ForgedActorIdsAreRefusedAndTheNextSnapshotLoads) {
  ReplayServiceOptions options = Options(false, 100);
  Replica saved(options);
  saved.Publish(channels::kTransitions, FlatBatch(0, 2, std::numeric_limits<int32_t>::max()),
                "actor-x");
  constexpr int kIds = 66000;  // more than the 65536 a snapshot held before ids were bounded
  for (int id = 0; id < kIds; ++id) {
    saved.Publish(channels::kTransitions, FlatBatch(id, 1, id), "actor-x");
  }
  EXPECT_EQ(saved.service().total_inserts(), options.max_actors);
  EXPECT_EQ(saved.service().counters().batches_refused, kIds - options.max_actors + 1);
  const std::string bytes = saved.Snapshot();
  Replica restored(options);
  EXPECT_EQ(ErrorOf([&] { restored.service().RestoreSnapshot(bytes); }), "");
  EXPECT_EQ(restored.service().total_inserts(), options.max_actors);
  ReplayServiceOptions fewer = options;
  fewer.max_actors = 8;
  EXPECT_NE(LoadError(bytes, fewer).find("holds actor id 8, this replay stores ids below 8"),
            std::string::npos);
}

TEST_F(ReplaySnapshotTest, AReplayThatHasServedRefusesToLoad) {
  Replica saved(Options(false));
  FillFlat(&saved);
  EXPECT_THROW(saved.service().RestoreSnapshot(saved.Snapshot()), std::logic_error);
}

}  // namespace
}  // namespace rl::replay
