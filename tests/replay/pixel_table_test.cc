#include "replay/pixel_table.h"

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <random>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "replay/prioritized_sampler.h"

namespace rl::replay {
namespace {

// Small frames keep most tests fast; the memory tests use Atari's 84 x 84.
constexpr int kHeight = 6;
constexpr int kWidth = 5;
constexpr int kStack = 3;

// Pixel p of frame `id` of the actor whose frames have content key `key`: a hash, so that any
// two frames differ.
uint8_t Pixel(int64_t key, int64_t id, size_t p) {
  uint64_t x = static_cast<uint64_t>(key) * 0x9E3779B97F4A7C15ULL +
               static_cast<uint64_t>(id) * 0xBF58476D1CE4E5B9ULL + p * 0x94D049BB133111EBULL;
  x ^= x >> 31;
  x *= 0xBF58476D1CE4E5B9ULL;
  x ^= x >> 29;
  return static_cast<uint8_t>(x >> 56);
}

// The bytes of the frames `ids` of content key `key`, one after the other.
std::vector<uint8_t> Frames(int64_t key, const std::vector<int64_t>& ids, size_t frame_bytes) {
  std::vector<uint8_t> bytes;
  for (int64_t id : ids) {
    for (size_t p = 0; p < frame_bytes; ++p) bytes.push_back(Pixel(key, id, p));
  }
  return bytes;
}

// A batch that owns its arrays.
struct OwnedPixelBatch {
  int32_t actor_id = 0;
  int64_t key = 0;  // content key of its frames
  int height = kHeight;
  int width = kWidth;
  int stack = kStack;
  std::vector<int64_t> frame_id;
  std::vector<uint8_t> frames;
  std::vector<int64_t> obs_frames, next_obs_frames, episode_id;
  std::vector<float> action;
  std::vector<float> reward, discount, priority;

  TransitionBatchView view() const {
    TransitionBatchView v;
    v.count = static_cast<int>(reward.size());
    v.columns = ColumnsView{1, action, reward, discount, episode_id, priority};
    v.actor_id = actor_id;
    v.height = height;
    v.width = width;
    v.stack = stack;
    v.num_frames = static_cast<int>(frame_id.size());
    v.frame_id = frame_id;
    v.frames = frames;
    v.obs_frames = obs_frames;
    v.next_obs_frames = next_obs_frames;
    return v;
  }
  void AddFrame(int64_t id) {
    frame_id.push_back(id);
    const std::vector<uint8_t> bytes =
        Frames(key, {id}, static_cast<size_t>(height) * static_cast<size_t>(width));
    frames.insert(frames.end(), bytes.begin(), bytes.end());
  }
};

// What a stored transition must read back as.
struct Expected {
  int64_t key = 0;
  std::vector<int64_t> obs, next_obs;
  float action = 0;
  float reward = 0.0f;
  float discount = 0.0f;
};

// An actor playing episodes: every step sends one new frame and the transition from the
// current stack to the next; an episode's first frame is repeated to fill the stack.
class FakeActor {
 public:
  // `key` sets the frames' content (by default the actor id; a restarted actor gets another).
  FakeActor(int32_t actor_id, int stack, int64_t key = -1)
      : actor_id_(actor_id), stack_(stack), key_(key >= 0 ? key : actor_id) {}

  OwnedPixelBatch NewBatch(int height = kHeight, int width = kWidth) const {
    OwnedPixelBatch b;
    b.actor_id = actor_id_;
    b.key = key_;
    b.height = height;
    b.width = width;
    b.stack = stack_;
    return b;
  }
  // Starts an episode: sends its first frame.
  void Reset(OwnedPixelBatch* b) {
    const int64_t f = next_id_++;
    b->AddFrame(f);
    current_.assign(static_cast<size_t>(stack_), f);
  }
  // A new batch that starts an episode.
  OwnedPixelBatch NewEpisode(int height = kHeight, int width = kWidth) {
    OwnedPixelBatch b = NewBatch(height, width);
    Reset(&b);
    return b;
  }
  // One step: sends a new frame and the transition; returns what it must read back as.
  Expected Step(OwnedPixelBatch* b, bool terminal = false, float priority = 0.0f) {
    const int64_t f = next_id_++;
    b->AddFrame(f);
    std::vector<int64_t> next(current_.begin() + 1, current_.end());
    next.push_back(f);
    Expected e{key_,
               current_,
               next,
               static_cast<float>(f % 4),
               0.5f * static_cast<float>(f),
               terminal ? 0.0f : 0.99f};
    AddTransition(b, e, priority);
    current_ = next;
    return e;
  }
  // Appends a transition naming any frames.
  static void AddTransition(OwnedPixelBatch* b, const Expected& e, float priority = 0.0f) {
    b->obs_frames.insert(b->obs_frames.end(), e.obs.begin(), e.obs.end());
    b->next_obs_frames.insert(b->next_obs_frames.end(), e.next_obs.begin(), e.next_obs.end());
    b->action.push_back(e.action);
    b->reward.push_back(e.reward);
    b->discount.push_back(e.discount);
    b->episode_id.push_back(0);
    b->priority.push_back(priority);
  }
  int64_t next_id() const { return next_id_; }

 private:
  int32_t actor_id_;
  int stack_;
  int64_t key_;
  int64_t next_id_ = 0;
  std::vector<int64_t> current_;
};

PixelTableOptions Options(int64_t capacity, int64_t frame_capacity = 0, int height = 0,
                          int width = 0, int stack = 0) {
  return {.capacity = capacity,
          .frame_capacity = frame_capacity,
          .height = height,
          .width = width,
          .stack = stack};
}

// Checks sampled transition i against `e`, byte for byte.
void ExpectTransition(const PixelSampleBatch& s, size_t i, const Expected& e) {
  const size_t frame_bytes = static_cast<size_t>(s.height) * static_cast<size_t>(s.width);
  const size_t stack_bytes = static_cast<size_t>(s.stack) * frame_bytes;
  const auto at = static_cast<std::ptrdiff_t>(i * stack_bytes);
  const auto end = static_cast<std::ptrdiff_t>((i + 1) * stack_bytes);
  EXPECT_TRUE(std::vector<uint8_t>(s.obs.begin() + at, s.obs.begin() + end) ==
              Frames(e.key, e.obs, frame_bytes))
      << "obs of draw " << i << " (index " << s.index[i] << ")";
  EXPECT_TRUE(std::vector<uint8_t>(s.next_obs.begin() + at, s.next_obs.begin() + end) ==
              Frames(e.key, e.next_obs, frame_bytes))
      << "next_obs of draw " << i << " (index " << s.index[i] << ")";
  EXPECT_EQ(s.action[i], e.action);
  EXPECT_EQ(s.reward[i], e.reward);
  EXPECT_EQ(s.discount[i], e.discount);
}

// Inserts into `table` a batch of `actor` that starts an episode and takes `steps` steps; returns
// what Insert() returns.
const char* InsertEpisode(PixelTable* table, FakeActor* actor, int steps) {
  OwnedPixelBatch b = actor->NewEpisode();
  for (int step = 0; step < steps; ++step) actor->Step(&b);
  return table->Insert(b.view());
}

// A batch of `count` stacks of the table's geometry.
PixelSampleBatch BatchFor(const PixelTable& table, int count) {
  PixelSampleBatch s;
  s.Resize(count, table.height(), table.width(), table.stack(), table.action_width());
  return s;
}

// Resizes `s` to `count` stacks of the table's geometry and draws them with a generator seeded
// with `seed`; returns what Sample() returns.
bool Draw(PixelTable* table, int count, uint64_t seed, PixelSampleBatch* s) {
  std::mt19937_64 rng(seed);
  *s = BatchFor(*table, count);
  return table->Sample(count, &rng, s->spans());
}

// Samples `count` transitions and checks each against log[index]; returns the indices seen.
std::set<int64_t> SampleAndCheck(PixelTable* table, const std::vector<Expected>& log, int count,
                                 uint64_t seed) {
  PixelSampleBatch s;
  EXPECT_TRUE(Draw(table, count, seed, &s));
  std::set<int64_t> seen;
  for (size_t i = 0; i < static_cast<size_t>(count); ++i) {
    const int64_t index = s.index[i];
    EXPECT_TRUE(index >= 0 && index < static_cast<int64_t>(log.size())) << index;
    if (index < 0 || index >= static_cast<int64_t>(log.size())) continue;
    ExpectTransition(s, i, log[static_cast<size_t>(index)]);
    seen.insert(index);
  }
  return seen;
}

TEST(PixelTableTest, DefaultOptionsAreValid) {
  EXPECT_NO_THROW(PixelTableOptions{}.Validate());
  EXPECT_EQ(PixelTableOptions{}.frames_kept(), 100000 + 3125 + 4096);
}

TEST(PixelTableTest, RefusesBadOptions) {
  EXPECT_THROW(PixelTable(Options(0)), std::invalid_argument);
  EXPECT_THROW(PixelTable(Options(10, -1)), std::invalid_argument);
  EXPECT_THROW(PixelTable(Options(10, 0, -1)), std::invalid_argument);
  EXPECT_THROW(PixelTable(Options(10, 0, 84, 5000)), std::invalid_argument);
  EXPECT_THROW(PixelTable(Options(10, 0, 84, 84, 65)), std::invalid_argument);
  EXPECT_NO_THROW(PixelTable(Options(10, 0, 84, 84, 4)));
}

TEST(PixelTableTest, StoresEachFrameOnceAndReportsItsMemory) {
  // 84 x 84 stacks of 4, capacity 1000, default frame capacity 1000 + 31 + 4096.
  constexpr int64_t kFrames = 1000 + 31 + 4096;
  constexpr int64_t kFrameBytes = 84 * 84;
  PixelTable table(Options(1000, 0, 84, 84, 4));
  EXPECT_EQ(table.frame_capacity(), kFrames);
  // Frames, 2 * 4 frame numbers and 28 bytes of fields per slot, 16 bytes of uniform sampler.
  const int64_t expected = kFrames * kFrameBytes + 1000 * (64 + 28) + 1000 * 16;
  EXPECT_NEAR(static_cast<double>(table.memory_bytes()), static_cast<double>(expected),
              0.01 * static_cast<double>(expected));

  // 1500 transitions in episodes of 100 steps: one frame per step and one per reset, however
  // many transitions name each frame.
  FakeActor actor(0, 4);
  for (int episode = 0; episode < 15; ++episode) {
    OwnedPixelBatch b = actor.NewEpisode(84, 84);
    for (int step = 0; step < 100; ++step) actor.Step(&b, step == 99);
    ASSERT_EQ(table.Insert(b.view()), nullptr);
  }
  EXPECT_EQ(table.total_inserts(), 1500);
  EXPECT_EQ(table.size(), 1000);
  EXPECT_EQ(table.total_frames(), 1515);
  // Storage did not grow beyond the actor's id window (64 KiB).
  EXPECT_NEAR(static_cast<double>(table.memory_bytes()), static_cast<double>(expected + 65536),
              0.01 * static_cast<double>(expected));
}

TEST(PixelTableTest, CostsAboutOneFrameAndUnder200BytesPerTransition) {
  // With a frame per transition (frame_capacity = capacity), what is not frames is the
  // per-transition overhead, the actor's window and the sampler included.
  constexpr int64_t kCapacity = 2000;
  constexpr int64_t kFrameBytes = 84 * 84;
  PixelTable uniform(Options(kCapacity, kCapacity, 84, 84, 4));
  PixelTable prioritized(Options(kCapacity, kCapacity, 84, 84, 4),
                         std::make_unique<PrioritizedSampler>(kCapacity, 0.6));
  FakeActor actor(0, 4);
  OwnedPixelBatch b = actor.NewEpisode(84, 84);
  for (int step = 0; step < 200; ++step) actor.Step(&b);
  ASSERT_EQ(uniform.Insert(b.view()), nullptr);
  ASSERT_EQ(prioritized.Insert(b.view()), nullptr);
  for (const PixelTable* table : {&uniform, &prioritized}) {
    const double overhead =
        static_cast<double>(table->memory_bytes() - kCapacity * kFrameBytes) / kCapacity;
    EXPECT_GT(overhead, 92.0);
    EXPECT_LT(overhead, 200.0);
  }
}

TEST(PixelTableTest, RebuildsStacksExactlyAcrossBatchesAndEpisodes) {
  PixelTable table(Options(100));
  FakeActor actor(1, kStack);
  std::vector<Expected> log;
  // Episodes of 4, 1 and 7 steps, in batches that name frames of earlier batches.
  OwnedPixelBatch b = actor.NewEpisode();
  log.push_back(actor.Step(&b));
  log.push_back(actor.Step(&b));
  ASSERT_EQ(table.Insert(b.view()), nullptr);
  b = actor.NewBatch();
  log.push_back(actor.Step(&b));
  log.push_back(actor.Step(&b, /*terminal=*/true));
  actor.Reset(&b);
  log.push_back(actor.Step(&b, /*terminal=*/true));
  ASSERT_EQ(table.Insert(b.view()), nullptr);
  b = actor.NewEpisode();  // a batch of one frame and no transition
  ASSERT_EQ(table.Insert(b.view()), nullptr);
  for (int step = 0; step < 7; ++step) {
    b = actor.NewBatch();
    log.push_back(actor.Step(&b, step == 6));
    ASSERT_EQ(table.Insert(b.view()), nullptr);
  }
  EXPECT_EQ(table.height(), kHeight);
  EXPECT_EQ(table.width(), kWidth);
  EXPECT_EQ(table.stack(), kStack);
  EXPECT_EQ(table.size(), 12);
  EXPECT_EQ(table.total_inserts(), 12);
  EXPECT_EQ(table.total_frames(), 15);
  EXPECT_EQ(table.transitions_missing_frames(), 0);

  const std::set<int64_t> seen = SampleAndCheck(&table, log, 600, 1);
  EXPECT_EQ(seen.size(), 12U);
  EXPECT_EQ(table.total_samples(), 600);
  EXPECT_EQ(table.stale_draws(), 0);
}

TEST(PixelTableTest, AStackOfTheRepeatedFirstFrameReadsBackAsThatFrame) {
  PixelTable table(Options(10));
  FakeActor actor(2, kStack);
  OwnedPixelBatch b = actor.NewEpisode();
  const Expected e = actor.Step(&b, /*terminal=*/true);
  ASSERT_EQ(e.obs, (std::vector<int64_t>{0, 0, 0}));
  ASSERT_EQ(e.next_obs, (std::vector<int64_t>{0, 0, 1}));
  ASSERT_EQ(table.Insert(b.view()), nullptr);
  PixelSampleBatch s;
  ASSERT_TRUE(Draw(&table, 4, /*seed=*/2, &s));
  for (size_t i = 0; i < 4; ++i) ExpectTransition(s, i, e);
  // The three frames of obs are the same bytes.
  const auto frame = static_cast<std::ptrdiff_t>(kHeight) * kWidth;
  EXPECT_TRUE(std::equal(s.obs.begin(), s.obs.begin() + frame, s.obs.begin() + 2 * frame));
}

TEST(PixelTableTest, KeepsTheFramesOfInterleavedActorsApartDespiteEqualLocalIds) {
  PixelTable table(Options(200));
  FakeActor a(3, kStack);
  FakeActor b(7, kStack);
  std::vector<Expected> log;
  OwnedPixelBatch ba = a.NewEpisode();
  OwnedPixelBatch bb = b.NewEpisode();
  for (int round = 0; round < 10; ++round) {
    // Both actors' ids run 0, 1, 2, ...; their batches alternate.
    for (int step = 0; step <= round % 3; ++step) log.push_back(a.Step(&ba));
    ASSERT_EQ(table.Insert(ba.view()), nullptr);
    ba = a.NewBatch();
    for (int step = 0; step <= (round + 1) % 4; ++step) log.push_back(b.Step(&bb));
    ASSERT_EQ(table.Insert(bb.view()), nullptr);
    bb = b.NewBatch();
  }
  ASSERT_EQ(table.size(), static_cast<int64_t>(log.size()));
  const std::set<int64_t> seen = SampleAndCheck(&table, log, 2000, 3);
  EXPECT_EQ(seen.size(), log.size());
}

TEST(PixelTableTest, SkipsOnlyTheTransitionsThatNameAnUnknownFrame) {
  PixelTable table(Options(50));
  FakeActor actor(1, kStack);
  OwnedPixelBatch b = actor.NewEpisode();
  // A transition naming a frame that was never sent, between two good ones.
  const Expected good = actor.Step(&b);
  Expected bad = good;
  bad.next_obs.back() = 999;
  FakeActor::AddTransition(&b, bad);
  std::vector<Expected> log = {good, actor.Step(&b)};
  ASSERT_EQ(table.Insert(b.view()), nullptr);
  EXPECT_EQ(table.size(), 2);
  EXPECT_EQ(table.transitions_missing_frames(), 1);

  // A lost message: its frames never arrive, so the transitions of the next batch that name
  // them are skipped, and the rest are stored.
  OwnedPixelBatch lost = actor.NewBatch();
  actor.Step(&lost);
  actor.Step(&lost);
  b = actor.NewBatch();
  // With stacks of 3, the next three transitions name a lost frame (3 or 4), the fourth none.
  for (int step = 0; step < 3; ++step) actor.Step(&b);
  log.push_back(actor.Step(&b));
  ASSERT_EQ(log.back().obs, (std::vector<int64_t>{5, 6, 7}));
  ASSERT_EQ(table.Insert(b.view()), nullptr);
  EXPECT_EQ(table.size(), 3);
  EXPECT_EQ(table.transitions_missing_frames(), 4);

  // Another actor's frames are not this actor's: actor 9 never sent frame 0.
  OwnedPixelBatch other = FakeActor(9, kStack).NewBatch();
  FakeActor::AddTransition(&other, log[0]);
  ASSERT_EQ(table.Insert(other.view()), nullptr);
  EXPECT_EQ(table.transitions_missing_frames(), 5);

  EXPECT_EQ(table.total_inserts(), 3);
  const std::set<int64_t> seen = SampleAndCheck(&table, log, 300, 4);
  EXPECT_EQ(seen.size(), 3U);
}

TEST(PixelTableTest, ForgetsIdsOlderThanTheActorsWindow) {
  // 4200 one-pixel frames, all still in the ring: id 100 shares its window entry with id 4196
  // and is forgotten, id 200 (3999 before the newest) is not.
  PixelTable table(Options(10, 10000, 1, 1, 1));
  FakeActor actor(0, 1);
  OwnedPixelBatch b = actor.NewBatch(1, 1);
  for (int i = 0; i < 4200; ++i) b.AddFrame(actor.next_id() + i);
  FakeActor::AddTransition(&b, Expected{0, {100}, {101}, 0, 0.0f, 1.0f});
  FakeActor::AddTransition(&b, Expected{0, {200}, {201}, 0, 0.0f, 1.0f});
  FakeActor::AddTransition(&b, Expected{0, {4198}, {4199}, 0, 0.0f, 1.0f});
  ASSERT_EQ(table.Insert(b.view()), nullptr);
  EXPECT_EQ(table.size(), 2);
  EXPECT_EQ(table.transitions_missing_frames(), 1);
}

TEST(PixelTableTest, ARestartedActorsOldIdsAreForgotten) {
  PixelTable table(Options(50));
  FakeActor first(4, kStack, /*key=*/40);
  ASSERT_EQ(InsertEpisode(&table, &first, 5), nullptr);
  ASSERT_EQ(table.size(), 5);

  // The same actor id starts again from frame 0, with other frames.
  FakeActor second(4, kStack, /*key=*/41);
  std::vector<Expected> log(5);
  OwnedPixelBatch b = second.NewEpisode();
  log.push_back(second.Step(&b));
  // Frame 4 was the first incarnation's; the second never sent it.
  FakeActor::AddTransition(&b, Expected{41, {0, 0, 4}, {0, 4, 1}, 0, 0.0f, 1.0f});
  ASSERT_EQ(table.Insert(b.view()), nullptr);
  EXPECT_EQ(table.size(), 6);
  EXPECT_EQ(table.transitions_missing_frames(), 1);
  // Transition 5 reads back with the new frames.
  PixelSampleBatch s;
  ASSERT_TRUE(Draw(&table, 200, /*seed=*/5, &s));
  int checked = 0;
  for (size_t i = 0; i < 200; ++i) {
    if (s.index[i] != 5) continue;
    ExpectTransition(s, i, log[5]);
    ++checked;
  }
  EXPECT_GT(checked, 0);
}

TEST(PixelTableTest, DrawsAgainInsteadOfReturningOverwrittenFrames) {
  // 31 frames (ids = global numbers 0 .. 30) in a ring of 20: frames 0 .. 10 are gone, so the
  // transitions t = 0 .. 12 (oldest frame max(t - 2, 0) <= 10) are stale and 13 .. 29 are not.
  PixelTable table(Options(100, 20));
  FakeActor actor(0, kStack);
  std::vector<Expected> log;
  OwnedPixelBatch b = actor.NewEpisode();
  for (int batch = 0; batch < 6; ++batch) {
    for (int step = 0; step < 5; ++step) log.push_back(actor.Step(&b));
    ASSERT_EQ(table.Insert(b.view()), nullptr);
    b = actor.NewBatch();
  }
  ASSERT_EQ(table.total_inserts(), 30);
  ASSERT_EQ(table.total_frames(), 31);
  ASSERT_EQ(table.size(), 30);

  const std::set<int64_t> seen = SampleAndCheck(&table, log, 3000, 6);
  EXPECT_EQ(*seen.begin(), 13);
  EXPECT_EQ(seen.size(), 17U);
  EXPECT_GE(table.stale_draws(), 13);
  EXPECT_EQ(table.size(), 17);
  EXPECT_EQ(table.total_samples(), 3000);
  // Dropped transitions take no priority updates.
  std::vector<int64_t> index(30);
  for (int64_t i = 0; i < 30; ++i) index[static_cast<size_t>(i)] = i;
  EXPECT_EQ(table.UpdatePriorities(index, std::vector<float>(30, 1.0f)), 17);

  // A new transition naming an overwritten frame is not stored.
  b = actor.NewBatch();
  FakeActor::AddTransition(&b, log[5]);
  ASSERT_EQ(table.Insert(b.view()), nullptr);
  EXPECT_EQ(table.transitions_missing_frames(), 1);
}

TEST(PixelTableTest, SweepsAwayStaleTransitionsWhenMostOfTheMassIsStale) {
  // Stack 1 and a ring of 3 frames: of 200 transitions (frames t, t + 1), only 198 and 199 keep
  // their frames. A draw meets 16 stale ones in a row, and the table is swept.
  PixelTable table(Options(200, 3, 2, 2, 1));
  FakeActor actor(0, 1);
  std::vector<Expected> log;
  OwnedPixelBatch b = actor.NewEpisode(2, 2);
  ASSERT_EQ(table.Insert(b.view()), nullptr);
  for (int step = 0; step < 200; ++step) {
    b = actor.NewBatch(2, 2);
    log.push_back(actor.Step(&b));
    ASSERT_EQ(table.Insert(b.view()), nullptr);
  }
  ASSERT_EQ(table.size(), 200);
  const std::set<int64_t> seen = SampleAndCheck(&table, log, 64, 7);
  EXPECT_EQ(seen, (std::set<int64_t>{198, 199}));
  EXPECT_EQ(table.size(), 2);
  EXPECT_GE(table.stale_draws(), 16);
}

TEST(PixelTableTest, SampleReturnsFalseAndWritesNothingWhenEveryTransitionIsStale) {
  PixelTable table(Options(10, 8, kHeight, kWidth, 2));
  FakeActor actor(0, 2);
  ASSERT_EQ(InsertEpisode(&table, &actor, 3), nullptr);
  // Eight more frames overwrite all four.
  OwnedPixelBatch b = actor.NewBatch();
  for (int i = 0; i < 8; ++i) b.AddFrame(actor.next_id() + i);
  ASSERT_EQ(table.Insert(b.view()), nullptr);
  ASSERT_EQ(table.size(), 3);

  std::mt19937_64 rng(8);
  PixelSampleBatch s = BatchFor(table, 5);
  std::fill(s.obs.begin(), s.obs.end(), 0xAB);
  std::fill(s.index.begin(), s.index.end(), -7);
  EXPECT_FALSE(table.Sample(5, &rng, s.spans()));
  EXPECT_EQ(table.size(), 0);
  EXPECT_EQ(table.stale_draws(), 3);
  EXPECT_EQ(table.total_samples(), 0);
  for (uint8_t v : s.obs) ASSERT_EQ(v, 0xAB);
  for (int64_t v : s.index) ASSERT_EQ(v, -7);
  EXPECT_FALSE(table.Sample(5, &rng, s.spans()));
}

TEST(PixelTableTest, RefusesBadBatchesAndStoresNoneOfThem) {
  PixelTable table(Options(50));
  FakeActor actor(1, kStack);
  ASSERT_EQ(InsertEpisode(&table, &actor, 1), nullptr);
  const int64_t frames = table.total_frames();

  auto refused = [&](const TransitionBatchView& view, const char* what) {
    const char* why = table.Insert(view);
    EXPECT_NE(why, nullptr) << what;
    if (why != nullptr) {
      EXPECT_FALSE(std::string(why).empty());
    }
    EXPECT_EQ(table.total_frames(), frames) << what;
    EXPECT_EQ(table.size(), 1) << what;
  };
  OwnedPixelBatch next = actor.NewBatch();
  actor.Step(&next);

  TransitionBatchView v = next.view();
  v.height = kHeight + 1;
  refused(v, "height");
  v = next.view();
  v.stack = kStack - 1;
  refused(v, "stack");
  v = next.view();
  v.width = 0;
  refused(v, "zero width");
  v = next.view();
  v.frames = v.frames.first(v.frames.size() - 1);
  refused(v, "frames short");
  v = next.view();
  v.frame_id = {};
  refused(v, "frame_id short");
  v = next.view();
  v.obs_frames = v.obs_frames.first(2);
  refused(v, "obs_frames short");
  v = next.view();
  v.columns.reward = {};
  refused(v, "reward short");
  v = next.view();
  v.columns.priority = v.columns.priority.first(0);
  v.columns.discount = v.columns.discount.first(0);
  refused(v, "discount short");
  v = next.view();
  v.columns.episode_id = std::span<const int64_t>(v.obs_frames);
  refused(v, "episode_id neither empty nor count");
  v = next.view();
  v.columns.action = {};
  refused(v, "action short");
  v = next.view();
  v.columns.action_width = 2;
  refused(v, "action width 2 with one value each");
  v = next.view();
  v.actor_id = -1;
  refused(v, "actor -1");
  v.actor_id = 65536;
  refused(v, "actor 65536");
  refused(TransitionBatchView{}, "empty");
  OwnedPixelBatch repeated = actor.NewBatch();
  repeated.AddFrame(10);
  repeated.AddFrame(10);
  refused(repeated.view(), "frame ids not increasing");

  // The good batch still goes in, with episode ids and priorities left out.
  v = next.view();
  v.columns.episode_id = {};
  v.columns.priority = {};
  EXPECT_EQ(table.Insert(v), nullptr);
  EXPECT_EQ(table.size(), 2);
}

TEST(PixelTableTest, RefusesAGeometryOtherThanTheConfiguredOneBeforeTheFirstBatch) {
  PixelTable table(Options(10, 0, kHeight, 0, 0));
  FakeActor actor(1, kStack);
  OwnedPixelBatch b = actor.NewEpisode(kHeight + 2, kWidth);
  EXPECT_NE(table.Insert(b.view()), nullptr);
  EXPECT_EQ(table.height(), 0);
  EXPECT_EQ(table.memory_bytes(), 10 * 16);  // only the sampler so far
}

TEST(PixelTableTest, WorksWithThePrioritizedSampler) {
  // Three transitions of priorities 1, 2 and 5 (alpha 1): P = 1/8, 2/8, 5/8, and with beta = 1
  // the weights are 1, 1/2, 1/5 (see the ReplayTable test of the same numbers).
  PixelTable table(Options(8), std::make_unique<PrioritizedSampler>(8, 1.0, 1e-9));
  FakeActor actor(0, kStack);
  std::vector<Expected> log;
  OwnedPixelBatch b = actor.NewEpisode();
  for (float priority : {1.0f, 2.0f, 5.0f}) log.push_back(actor.Step(&b, false, priority));
  ASSERT_EQ(table.Insert(b.view()), nullptr);

  std::mt19937_64 rng(9);
  PixelSampleBatch s = BatchFor(table, 8000);
  ASSERT_TRUE(table.Sample(8000, &rng, s.spans()));
  std::vector<int> hits(3, 0);
  const float weight[3] = {1.0f, 0.5f, 0.2f};
  for (size_t i = 0; i < 8000; ++i) {
    const auto v = static_cast<size_t>(s.index[i]);
    ASSERT_LT(v, 3U);
    ++hits[v];
    EXPECT_NEAR(s.weight[i], weight[v], 1e-6);
    if (i < 100) ExpectTransition(s, i, log[v]);
  }
  EXPECT_NEAR(hits[0], 1000, 5);
  EXPECT_NEAR(hits[1], 2000, 5);
  EXPECT_NEAR(hits[2], 5000, 5);

  // New priorities for the sampled indices (and two that do not exist).
  const std::vector<int64_t> index = {0, 1, 2, 3, -1};
  const std::vector<float> priority = {5.0f, 2.0f, 1.0f, 9.0f, 9.0f};
  EXPECT_EQ(table.UpdatePriorities(index, priority), 3);
  EXPECT_NEAR(table.sampler().Probability(0), 5.0 / 8.0, 1e-6);
  EXPECT_NEAR(table.sampler().Probability(2), 1.0 / 8.0, 1e-6);
  table.set_importance_exponent(0.0);
  ASSERT_TRUE(table.Sample(8000, &rng, s.spans()));
  for (float w : s.weight) ASSERT_EQ(w, 1.0f);
}

TEST(PixelTableTest, UpdatePrioritiesSkipsOverwrittenTransitions) {
  // Capacity 4 after 6 transitions: 2 .. 5 are stored.
  PixelTable table(Options(4), std::make_unique<PrioritizedSampler>(4, 1.0, 1e-9));
  FakeActor actor(0, kStack);
  ASSERT_EQ(InsertEpisode(&table, &actor, 6), nullptr);
  const std::vector<int64_t> index = {0, 1, 2, 5, 6};
  EXPECT_EQ(table.UpdatePriorities(index, std::vector<float>{7, 7, 7, 7, 7}), 2);
  EXPECT_THROW(table.set_importance_exponent(2.0), std::invalid_argument);
}

TEST(PixelTableDeathTest, AbortsWhenTheOutputHasTheWrongSize) {
  PixelTable table(Options(10));
  FakeActor actor(0, kStack);
  ASSERT_EQ(InsertEpisode(&table, &actor, 1), nullptr);
  std::mt19937_64 rng(1);
  PixelSampleBatch s = BatchFor(table, 4);
  EXPECT_DEATH(table.Sample(5, &rng, s.spans()), "batch_size");
}

}  // namespace
}  // namespace rl::replay
