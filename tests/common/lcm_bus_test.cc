#include "common/lcm_bus.h"

#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cmath>
#include <limits>
#include <memory>
#include <set>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "common/channels.h"
#include "common/host_ports.h"
#include "common/message_auth.h"
#include "common/message_examples.h"

namespace rl {
namespace {

BusConfig MemqConfig(int64_t run_id, const std::string& sender) {
  return InProcessBusConfig(run_id, sender);
}

rlmsg::transition_batch_t MakeBatch(int count, int obs_size) {
  return examples::FlatTransitions(0, count, obs_size, 1, /*actor=*/1);
}

// Encoded as actor-1 of run 42 would send it now (a fresh time, an incarnation just before it).
std::vector<uint8_t> Encode(rlmsg::transition_batch_t m) {
  m.header.run_id = 42;
  m.header.sender = "actor-1";
  m.header.utime = WallMicros();
  m.header.incarnation = m.header.utime - 1000;
  std::vector<uint8_t> bytes(static_cast<size_t>(m.getEncodedSize()));
  m.encode(bytes.data(), 0, static_cast<int>(bytes.size()));
  return bytes;
}

class BusTest : public ::testing::Test {
 protected:
  explicit BusTest(BusConfig config = MemqConfig(42, "actor-1")) : bus_(std::move(config)) {
    bus_.Subscribe<rlmsg::transition_batch_t>(
        channels::kTransitions, [this](const rlmsg::transition_batch_t& m) { got_.push_back(m); });
  }
  // Publishes `m` twice and handles what arrives: both copies.
  void PublishTwiceAndReceiveBoth(rlmsg::transition_batch_t m) {
    ASSERT_TRUE(bus_.Publish(channels::kTransitions, &m));
    ASSERT_TRUE(bus_.Publish(channels::kTransitions, &m));
    bus_.Handle(100);
    ASSERT_EQ(got_.size(), 2U);
  }
  Bus bus_;
  std::vector<rlmsg::transition_batch_t> got_;
};

TEST_F(BusTest, DeliversAGoodMessageWithItsHeaderFilled) {
  ASSERT_NO_FATAL_FAILURE(PublishTwiceAndReceiveBoth(MakeBatch(3, 4)));
  EXPECT_EQ(got_[0].header.run_id, 42);
  EXPECT_EQ(got_[0].header.sender, "actor-1");
  EXPECT_EQ(got_[0].header.seq, 0);
  EXPECT_EQ(got_[1].header.seq, 1);
  EXPECT_GT(got_[0].header.utime, 0);
  EXPECT_EQ(got_[1].obs.size(), 12U);
  EXPECT_EQ(bus_.counters().received, 2);
  EXPECT_EQ(bus_.counters().lost, 0);
}

TEST_F(BusTest, DropsAnotherRunsMessagesAsForeign) {
  auto bytes = Encode(MakeBatch(2, 4));
  rlmsg::transition_batch_t other = MakeBatch(2, 4);
  other.header.run_id = 43;
  other.header.sender = "actor-9";
  other.header.utime = WallMicros();
  std::vector<uint8_t> foreign(static_cast<size_t>(other.getEncodedSize()));
  other.encode(foreign.data(), 0, static_cast<int>(foreign.size()));
  bus_.PublishRaw(channels::kTransitions, foreign.data(), foreign.size());
  bus_.PublishRaw(channels::kTransitions, bytes.data(), bytes.size());
  bus_.Handle(100);
  EXPECT_EQ(got_.size(), 1U);
  EXPECT_EQ(bus_.counters().foreign, 1);
}

TEST_F(BusTest, DropsTruncatedAndForeignTypeBytesAsMalformed) {
  auto bytes = Encode(MakeBatch(2, 4));
  bus_.PublishRaw(channels::kTransitions, bytes.data(), bytes.size() - 5);  // truncated
  const std::vector<uint8_t> junk(64, 0x42);                                // unknown type
  bus_.PublishRaw(channels::kTransitions, junk.data(), junk.size());
  rlmsg::checkpoint_t ckpt{};  // a real message of another type
  ckpt.header.run_id = 42;
  ckpt.header.sender = "learner";
  ckpt.header.utime = WallMicros();
  ckpt.path = "x";
  std::vector<uint8_t> other(static_cast<size_t>(ckpt.getEncodedSize()));
  ckpt.encode(other.data(), 0, static_cast<int>(other.size()));
  bus_.PublishRaw(channels::kTransitions, other.data(), other.size());
  bytes.push_back(0);  // trailing byte
  bus_.PublishRaw(channels::kTransitions, bytes.data(), bytes.size());
  bus_.Handle(100);
  EXPECT_TRUE(got_.empty());
  EXPECT_EQ(bus_.counters().malformed, 4);
}

TEST_F(BusTest, RefusesAForgedArrayLengthBeforeDecoding) {
  auto bytes = Encode(MakeBatch(2, 4));
  // num_values follows the header ("actor-1") and actor_id, obs_size and count (12): claim two
  // billion floats.
  const size_t at = MacOffset(7) + kMacBytes + 12;
  bytes[at] = 0x7F;
  bytes[at + 1] = 0xFF;
  bus_.PublishRaw(channels::kTransitions, bytes.data(), bytes.size());
  // A negative string length in the header.
  auto neg = Encode(MakeBatch(2, 4));
  neg[16] = 0xFF;
  bus_.PublishRaw(channels::kTransitions, neg.data(), neg.size());
  bus_.Handle(100);
  EXPECT_TRUE(got_.empty());
  EXPECT_EQ(bus_.counters().malformed, 2);
}

TEST_F(BusTest, DropsNonFiniteOrInconsistentContentAsInvalid) {
  auto nan = MakeBatch(2, 4);
  nan.reward[1] = std::numeric_limits<float>::quiet_NaN();
  bus_.Publish(channels::kTransitions, &nan);
  auto bad_discount = MakeBatch(2, 4);
  bad_discount.discount[0] = 1.5f;
  bus_.Publish(channels::kTransitions, &bad_discount);
  // Actions are floats of the env's width: a negative one may be a continuous action, so the
  // message checks refuse a non-finite one (the replay checks range against the env).
  auto bad_action = MakeBatch(2, 4);
  bad_action.action[0] = std::numeric_limits<float>::infinity();
  bus_.Publish(channels::kTransitions, &bad_action);
  bus_.Handle(100);
  EXPECT_TRUE(got_.empty());
  EXPECT_EQ(bus_.counters().invalid, 3);
}

TEST_F(BusTest, CountsSequenceGapsAsLost) {
  for (int seq : {0, 1, 4, 5, 9}) {
    auto m = MakeBatch(1, 4);
    m.header.run_id = 42;
    m.header.sender = "actor-1";
    m.header.seq = seq;
    m.header.utime = WallMicros();
    std::vector<uint8_t> bytes(static_cast<size_t>(m.getEncodedSize()));
    m.encode(bytes.data(), 0, static_cast<int>(bytes.size()));
    bus_.PublishRaw(channels::kTransitions, bytes.data(), bytes.size());
  }
  bus_.Handle(100);
  EXPECT_EQ(got_.size(), 5U);
  EXPECT_EQ(bus_.counters().lost, 2 + 3);
}

// A handler may keep a message by swapping its contents out (the learner keeps its sample
// replies so). The next message then decodes into what the handler left behind, here arrays of
// other lengths and values, and must come out whole.
TEST(BusSwapTest, AHandlerMaySwapAMessageOutAndTheNextDecodesIntoWhatItLeft) {
  Bus bus(MemqConfig(42, "actor-1"));
  std::vector<rlmsg::transition_batch_t> kept;
  bus.Subscribe<rlmsg::transition_batch_t>(channels::kTransitions,
                                           [&kept](rlmsg::transition_batch_t& m) {
                                             rlmsg::transition_batch_t leftover = MakeBatch(5, 7);
                                             leftover.obs.assign(1000, -1.0f);
                                             kept.push_back(std::move(leftover));
                                             std::swap(kept.back(), m);
                                           });
  std::vector<rlmsg::transition_batch_t> sent;
  for (const auto& [first, count] : std::vector<std::pair<int, int>>{{0, 3}, {10, 2}, {20, 4}}) {
    sent.push_back(examples::FlatTransitions(first, count, 4, 1, /*actor=*/1));
    ASSERT_TRUE(bus.Publish(channels::kTransitions, &sent.back()));
    bus.Handle(100);
  }
  ASSERT_EQ(kept.size(), sent.size());
  for (size_t i = 0; i < sent.size(); ++i) {
    SCOPED_TRACE(i);
    EXPECT_EQ(kept[i].count, sent[i].count);
    EXPECT_EQ(kept[i].obs, sent[i].obs);
    EXPECT_EQ(kept[i].next_obs, sent[i].next_obs);
    EXPECT_EQ(kept[i].reward, sent[i].reward);
    EXPECT_EQ(kept[i].header.seq, static_cast<int64_t>(i));
  }
  EXPECT_EQ(bus.counters().received, 3);
  EXPECT_EQ(bus.counters().invalid, 0);
}
// Authentication and freshness: a keyed bus, and messages made by hand as another process (or an
// attacker, or a recording) would send them.
const std::string kKey(kKeyBytes, 'k');

// Encodes a one-transition batch of run 42 from actor-2 with the given header (utime: now unless
// given), signed with `key` (unless empty).
std::vector<uint8_t> Stamped(int64_t incarnation, int64_t seq, const std::string& key,
                             int64_t run_id = 42, int64_t utime = -1) {
  auto m = MakeBatch(1, 4);
  m.header.run_id = run_id;
  m.header.sender = "actor-2";
  m.header.incarnation = incarnation;
  m.header.seq = seq;
  m.header.utime = utime < 0 ? WallMicros() : utime;
  std::vector<uint8_t> bytes(static_cast<size_t>(m.getEncodedSize()));
  m.encode(bytes.data(), 0, static_cast<int>(bytes.size()));
  if (!key.empty()) {
    MessageAuthenticator auth(key);
    EXPECT_TRUE(auth.Sign(channels::kTransitions, bytes.data(), bytes.size(),
                          MacOffset(m.header.sender.size())));
  }
  return bytes;
}

class KeyedBusTest : public BusTest {
 protected:
  KeyedBusTest() : BusTest(Keyed()) {}
  static BusConfig Keyed() {
    BusConfig c = MemqConfig(42, "replay");
    c.key = kKey;
    return c;
  }
  void Send(const std::vector<uint8_t>& bytes) {
    bus_.PublishRaw(channels::kTransitions, bytes.data(), bytes.size());
    bus_.Handle(100);
  }
};

TEST_F(KeyedBusTest, DeliversItsOwnSignedMessages) {
  ASSERT_NO_FATAL_FAILURE(PublishTwiceAndReceiveBoth(MakeBatch(2, 4)));
  EXPECT_EQ(got_[0].header.incarnation, bus_.incarnation());
  EXPECT_EQ(bus_.counters().dropped(), 0);
}

// What authentication costs: the time of each signature and each check adds up, and only there.
TEST_F(KeyedBusTest, TimesItsSignaturesAndChecks) {
  EXPECT_EQ(bus_.counters().mac_nanos, 0);
  auto m = MakeBatch(2, 4);
  ASSERT_TRUE(bus_.Publish(channels::kTransitions, &m));
  const int64_t signed_only = bus_.counters().mac_nanos;
  EXPECT_GT(signed_only, 0);
  bus_.Handle(100);
  ASSERT_EQ(got_.size(), 1U);
  EXPECT_GT(bus_.counters().mac_nanos, signed_only);
}

TEST_F(BusTest, WithoutAKeySpendsNoTimeOnMacs) {
  auto m = MakeBatch(2, 4);
  ASSERT_TRUE(bus_.Publish(channels::kTransitions, &m));
  bus_.Handle(100);
  ASSERT_EQ(got_.size(), 1U);
  EXPECT_EQ(bus_.counters().mac_nanos, 0);
}

TEST_F(KeyedBusTest, DropsNoMacAWrongKeyAndEveryFlippedBitAsUnauthenticated) {
  Send(Stamped(1, 0, ""));                           // no MAC
  Send(Stamped(1, 1, std::string(kKeyBytes, 'x')));  // another run's key
  const std::vector<uint8_t> good = Stamped(1, 2, kKey);
  int64_t flips = 0;
  for (size_t byte = 0; byte < good.size(); ++byte) {
    for (int bit = 0; bit < 8; ++bit) {
      std::vector<uint8_t> bad = good;
      bad[byte] ^= static_cast<uint8_t>(1 << bit);
      bus_.PublishRaw(channels::kTransitions, bad.data(), bad.size());
      ++flips;
    }
    bus_.Handle(0);
  }
  bus_.Handle(100);
  // A flip in the fingerprint, a length or the run id is caught earlier (malformed, foreign);
  // every other flip by the MAC. None reaches the handler, and the good message still does.
  EXPECT_TRUE(got_.empty());
  const BusCounters& c = bus_.counters();
  EXPECT_EQ(c.malformed + c.foreign + c.unauthenticated, flips + 2);
  EXPECT_GE(c.unauthenticated, flips / 2);
  EXPECT_EQ(c.replayed + c.invalid + c.received, 0);
  Send(good);
  EXPECT_EQ(got_.size(), 1U);
}

// The MAC binds the channel: a signed message moved to another channel of the same type is
// dropped.
TEST_F(KeyedBusTest, DropsAMessageSignedForAnotherChannel) {
  auto m = MakeBatch(1, 4);
  m.header.run_id = 42;
  m.header.sender = "actor-2";
  m.header.incarnation = 1;
  m.header.seq = 0;
  m.header.utime = WallMicros();
  std::vector<uint8_t> bytes(static_cast<size_t>(m.getEncodedSize()));
  m.encode(bytes.data(), 0, static_cast<int>(bytes.size()));
  MessageAuthenticator auth(kKey);
  ASSERT_TRUE(auth.Sign("RL_OTHER", bytes.data(), bytes.size(), MacOffset(7)));
  Send(bytes);
  EXPECT_TRUE(got_.empty());
  EXPECT_EQ(bus_.counters().unauthenticated, 1);
}

TEST_F(KeyedBusTest, DropsAnotherRunsMessagesAsForeignBeforeCheckingTheirMac) {
  Send(Stamped(1, 0, std::string(kKeyBytes, 'x'), /*run_id=*/43));
  EXPECT_EQ(bus_.counters().foreign, 1);
  EXPECT_EQ(bus_.counters().unauthenticated, 0);
}

TEST_F(KeyedBusTest, DropsReplayedMessagesAndCountsNothingLost) {
  const auto first = Stamped(5, 0, kKey), second = Stamped(5, 1, kKey);
  for (const auto* bytes : {&first, &second, &first, &second, &second}) Send(*bytes);
  EXPECT_EQ(got_.size(), 2U);
  EXPECT_EQ(bus_.counters().replayed, 3);
  EXPECT_EQ(bus_.counters().lost, 0);
}

TEST_F(KeyedBusTest, ARestartedSenderStartsItsSequenceAgainAndItsOldSelfIsReplayed) {
  Send(Stamped(5, 0, kKey));
  Send(Stamped(5, 9, kKey));  // 8 lost
  Send(Stamped(6, 0, kKey));  // restarted: a new sequence, nothing lost
  Send(Stamped(6, 1, kKey));
  Send(Stamped(5, 10, kKey));  // the old incarnation, recorded and played back
  EXPECT_EQ(got_.size(), 4U);
  EXPECT_EQ(bus_.counters().lost, 8);
  EXPECT_EQ(bus_.counters().replayed, 1);
  rlmsg::stats_replay_t stats{};
  bus_.FillCounters(&stats);
  EXPECT_EQ(stats.dropped_replayed, 1);
  EXPECT_EQ(stats.lost, 8);
}

TEST_F(KeyedBusTest, AForgedHugeGapSaturatesLostAndANegativeSequenceIsInvalid) {
  Send(Stamped(5, 0, kKey));
  Send(Stamped(5, std::numeric_limits<int64_t>::max(), kKey));
  Send(Stamped(6, 0, kKey));
  Send(Stamped(6, std::numeric_limits<int64_t>::max(), kKey));  // the sum would overflow
  EXPECT_EQ(bus_.counters().lost, std::numeric_limits<int64_t>::max());
  Send(Stamped(7, -3, kKey));
  Send(Stamped(-1, 4, kKey));
  EXPECT_EQ(bus_.counters().invalid, 2);
  EXPECT_EQ(got_.size(), 4U);
}

TEST_F(KeyedBusTest, TwoSubscriptionsOfAChannelEachGetEveryFreshMessageAndCountGapsOnce) {
  std::vector<int64_t> second;
  bus_.Subscribe<rlmsg::transition_batch_t>(
      channels::kTransitions,
      [&second](const rlmsg::transition_batch_t& m) { second.push_back(m.header.seq); });
  for (int64_t seq : {0, 1, 4, 4}) Send(Stamped(5, seq, kKey));
  EXPECT_EQ(got_.size(), 3U);
  EXPECT_EQ(second, (std::vector<int64_t>{0, 1, 4}));
  EXPECT_EQ(bus_.counters().lost, 2);
}

TEST(BusKeyTest, AnUnkeyedBusAlsoDropsReplayedMessages) {
  Bus bus(MemqConfig(42, "replay"));
  int got = 0;
  bus.Subscribe<rlmsg::transition_batch_t>(channels::kTransitions,
                                           [&got](const rlmsg::transition_batch_t&) { ++got; });
  const auto bytes = Stamped(1, 0, "");
  for (int k = 0; k < 3; ++k) bus.PublishRaw(channels::kTransitions, bytes.data(), bytes.size());
  bus.Handle(100);
  EXPECT_EQ(got, 1);
  EXPECT_EQ(bus.counters().replayed, 2);
}

TEST(BusHandlerTest, AThrowingHandlerIsCountedAndDoesNotEscape) {
  Bus bus(MemqConfig(1, "replay"));
  bus.Subscribe<rlmsg::transition_batch_t>(
      channels::kTransitions,
      [](const rlmsg::transition_batch_t&) { throw std::runtime_error("boom"); });
  auto m = MakeBatch(1, 4);
  bus.Publish(channels::kTransitions, &m);
  EXPECT_NO_THROW(bus.Handle(100));
  EXPECT_EQ(bus.counters().invalid, 1);
}

TEST(BusOpenTest, ABadUrlThrowsWithTheUrlInTheMessage) {
  BusConfig c = MemqConfig(1, "x");
  c.url = "nosuchprovider://";
  try {
    Bus bus(c);
    FAIL() << "expected an exception";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("nosuchprovider://"), std::string::npos);
  }
}

// The freshness window, the replay check and the saved positions, with receive times chosen by
// the test (Bus::Deliver): messages of actor-2, signed, at times around t_ (now).
constexpr int64_t kSecond = 1'000'000;

class WindowTest : public ::testing::Test {
 protected:
  WindowTest() : bus_(Config()) { Watch(&bus_, &got_); }
  static BusConfig Config() {
    BusConfig c = MemqConfig(42, "replay");
    c.key = kKey;
    c.max_message_age = 60 * kSecond;
    c.max_clock_skew = 10 * kSecond;
    return c;
  }
  static void Watch(Bus* bus, std::vector<int64_t>* got) {
    bus->Subscribe<rlmsg::transition_batch_t>(
        channels::kTransitions,
        [got](const rlmsg::transition_batch_t& m) { got->push_back(m.header.seq); });
  }
  // Delivers actor-2's message (incarnation, seq, utime) as received at `at`.
  static void Send(Bus* bus, int64_t incarnation, int64_t seq, int64_t utime, int64_t at) {
    const auto bytes = Stamped(incarnation, seq, kKey, 42, utime);
    bus->Deliver(channels::kTransitions, bytes.data(), bytes.size(), at);
  }
  void Send(int64_t incarnation, int64_t seq, int64_t utime, int64_t at) {
    Send(&bus_, incarnation, seq, utime, at);
  }
  const int64_t t_ = WallMicros();
  Bus bus_;
  std::vector<int64_t> got_;
};

TEST_F(WindowTest, DropsWhatIsOlderThanTheWindowOrAheadOfTheSkewAsStale) {
  const int64_t inc = t_ - 3600 * kSecond;
  Send(inc, 0, t_ - 61 * kSecond, t_);           // a minute and a second old
  Send(inc, 1, t_ + 11 * kSecond, t_);           // 11 s ahead
  Send(t_ + 10 * kSecond, 2, t_ - kSecond, t_);  // started 11 s after it was sent
  EXPECT_EQ(bus_.counters().stale, 3);
  Send(inc, 3, t_ - 59 * kSecond, t_);
  Send(inc, 4, t_ + 9 * kSecond, t_);
  Send(t_ + 5 * kSecond, 0, t_ - 4 * kSecond, t_);  // within the skew
  EXPECT_EQ(got_, (std::vector<int64_t>{3, 4, 0}));
  EXPECT_EQ(bus_.counters().stale, 3);
  EXPECT_EQ(bus_.counters().dropped(), 3);
  rlmsg::stats_learner_t stats{};
  bus_.FillCounters(&stats);
  EXPECT_EQ(stats.dropped_stale, 3);
  EXPECT_EQ(Dropped(stats), 3);
}

// A holder of the key forges a message of actor-2 with a later incarnation, or a huge sequence
// number: the real actor-2 is dropped as replayed only until the forged position ages out.
TEST_F(WindowTest, AForgedLaterIncarnationOrSequenceSilencesItsSenderOnlyForTheWindow) {
  const int64_t inc = t_ - 3600 * kSecond;
  Send(inc, 0, t_, t_);
  Send(t_ + 9 * kSecond, 0, t_ + 9 * kSecond, t_);  // forged: a later incarnation
  Send(inc, 1, t_ + kSecond, t_ + kSecond);
  Send(inc, 2, t_ + 69 * kSecond, t_ + 69 * kSecond);  // the forged one is 60 s old: not yet
  EXPECT_EQ(bus_.counters().replayed, 2);
  Send(inc, 3, t_ + 69 * kSecond + 1, t_ + 69 * kSecond + 1);
  Send(inc, std::numeric_limits<int64_t>::max(), t_ + 70 * kSecond, t_ + 70 * kSecond);  // forged
  Send(inc, 4, t_ + 71 * kSecond, t_ + 71 * kSecond);
  Send(inc, 5, t_ + 130 * kSecond + 1, t_ + 130 * kSecond + 1);
  EXPECT_EQ(got_, (std::vector<int64_t>{0, 0, 3, std::numeric_limits<int64_t>::max(), 5}));
  EXPECT_EQ(bus_.counters().replayed, 3);
}

// What a restarted process loads from its state: recorded messages not newer than the saved
// positions are replayed even inside the window, newer ones flow, and nothing counts as lost.
TEST_F(WindowTest, SavedPositionsMakeARestartedBusRefuseRecordedTraffic) {
  const int64_t old_inc = t_ - 7200 * kSecond, inc = t_ - 3600 * kSecond;
  Send(old_inc, 0, t_ - 30 * kSecond, t_ - 30 * kSecond);
  Send(inc, 0, t_ - 20 * kSecond, t_ - 20 * kSecond);
  Send(inc, 1, t_ - 10 * kSecond, t_ - 10 * kSecond);
  ASSERT_EQ(got_.size(), 3U);
  const std::vector<StreamPosition> saved = bus_.Positions();
  ASSERT_EQ(saved.size(), 1U);  // (the positions older than the window are left out)
  EXPECT_EQ(saved[0].channel, channels::kTransitions);
  EXPECT_EQ(saved[0].sender, "actor-2");
  EXPECT_EQ(saved[0].incarnation, inc);
  EXPECT_EQ(saved[0].seq, 1);
  const std::string text = bus_.SavePositions();

  // Restored before and after subscribing.
  for (const bool before : {true, false}) {
    SCOPED_TRACE(before ? "restored before subscribing" : "restored after subscribing");
    Bus restarted(Config());
    std::vector<int64_t> got;
    if (before) restarted.LoadPositions(text);
    Watch(&restarted, &got);
    if (!before) restarted.LoadPositions(text);
    Send(&restarted, old_inc, 0, t_ - 30 * kSecond, t_);  // the recording, played back
    Send(&restarted, inc, 0, t_ - 20 * kSecond, t_);
    Send(&restarted, inc, 1, t_ - 10 * kSecond, t_);
    EXPECT_TRUE(got.empty());
    EXPECT_EQ(restarted.counters().replayed, 3);
    Send(&restarted, inc, 5, t_, t_);  // live: a gap since the save, not counted as lost
    Send(&restarted, inc, 7, t_, t_);  // one lost
    EXPECT_EQ(got, (std::vector<int64_t>{5, 7}));
    EXPECT_EQ(restarted.counters().lost, 1);
  }
  // Without them (today's restart), the recording is taken.
  Bus forgetful(Config());
  std::vector<int64_t> got;
  Watch(&forgetful, &got);
  Send(&forgetful, inc, 0, t_ - 20 * kSecond, t_);
  EXPECT_EQ(got.size(), 1U);
}

TEST_F(WindowTest, RestoringKeepsTheNewerOfTwoPositionsAndPositionsRoundTripAsText) {
  Send(t_ - 100, 9, t_, t_);
  bus_.RestorePositions({{channels::kTransitions, "actor-2", t_ - 100, 3, t_},
                         {channels::kTransitions, "actor-7", t_ - 50, 2, t_},
                         {"RL_ELSEWHERE", "learner", 5, 6, t_}});
  const auto positions = bus_.Positions();
  ASSERT_EQ(positions.size(), 3U);
  EXPECT_EQ(positions[0].channel, "RL_ELSEWHERE");  // no subscription: kept as restored
  EXPECT_EQ(positions[1].sender, "actor-2");
  EXPECT_EQ(positions[1].seq, 9);  // heard later than the restored 3
  EXPECT_EQ(positions[2].sender, "actor-7");
  const auto parsed = ParsePositions(FormatPositions(positions));
  ASSERT_EQ(parsed.size(), positions.size());
  for (size_t i = 0; i < parsed.size(); ++i) {
    EXPECT_EQ(parsed[i].channel, positions[i].channel);
    EXPECT_EQ(parsed[i].sender, positions[i].sender);
    EXPECT_EQ(parsed[i].incarnation, positions[i].incarnation);
    EXPECT_EQ(parsed[i].seq, positions[i].seq);
    EXPECT_EQ(parsed[i].utime, positions[i].utime);
  }
  EXPECT_TRUE(ParsePositions("").empty());
}

TEST(PositionsTextTest, RefusesWhatIsNotPositions) {
  for (const std::string& bad : std::vector<std::string>{
           "CH actor-1 1 2 3", "CH actor-1 1 2\n", "CH actor-1 1 2 3 4\n", "CH actor-1 1 2 x\n",
           "CH actor-1 -1 2 3\n", "CH actor-1 1 -2 3\n", "CH  1 2 3\n", "CH a\tb 1 2 3\n",
           " actor-1 1 2 3\n", "CH " + std::string(kMaxSenderBytes + 1, 'a') + " 1 2 3\n",
           std::string(64, 'C') + " a 1 2 3\n", "CH a 1 2 99999999999999999999\n"}) {
    EXPECT_THROW(ParsePositions(bad), std::runtime_error) << bad;
  }
  std::string many;
  for (size_t i = 0; i <= kMaxStoredPositions; ++i) many += "CH a 1 2 3\n";
  EXPECT_THROW(ParsePositions(many), std::runtime_error);
}

// The MAC and the freshness checks come before any decoding: a forged message whose body would
// not decode is unauthenticated, a signed one that is stale or replayed is counted so, not as
// malformed.
TEST_F(WindowTest, ChecksTheMacAndFreshnessBeforeDecoding) {
  std::vector<uint8_t> junk = Stamped(5, 0, "", 42, t_);
  junk.resize(junk.size() - 3);  // torn: would not decode
  auto send = [&](const std::vector<uint8_t>& m, int64_t at) {
    bus_.Deliver(channels::kTransitions, m.data(), m.size(), at);
  };
  std::vector<uint8_t> forged = junk;
  forged[MacOffset(7)] = 1;  // a MAC, wrong
  send(forged, t_);
  EXPECT_EQ(bus_.counters().unauthenticated, 1);
  MessageAuthenticator key_holder(kKey);
  ASSERT_TRUE(key_holder.Sign(channels::kTransitions, junk.data(), junk.size(), MacOffset(7)));
  send(junk, t_ + 61 * kSecond);
  EXPECT_EQ(bus_.counters().stale, 1);
  send(junk, t_);
  EXPECT_EQ(bus_.counters().malformed, 1);  // fresh: decoded, refused, position not taken
  Send(5, 0, t_, t_);
  send(junk, t_);
  EXPECT_EQ(bus_.counters().replayed, 1);
  EXPECT_EQ(bus_.counters().malformed, 1);
  EXPECT_EQ(got_, (std::vector<int64_t>{0}));
}

TEST(BusSenderTest, RefusesASenderNameUnfitForTheNonceAndDropsSuchMessagesAsMalformed) {
  EXPECT_THROW(Bus(InProcessBusConfig(1, "actor 1")), std::invalid_argument);
  EXPECT_THROW(Bus(InProcessBusConfig(1, std::string(kMaxSenderBytes + 1, 'a'))),
               std::invalid_argument);
  BusConfig bad_window = InProcessBusConfig(1, "replay");
  bad_window.max_message_age = 0;
  EXPECT_THROW(Bus{bad_window}, std::invalid_argument);
  Bus bus(InProcessBusConfig(42, "replay"));
  int got = 0;
  bus.Subscribe<rlmsg::transition_batch_t>(channels::kTransitions,
                                           [&got](const rlmsg::transition_batch_t&) { ++got; });
  auto m = MakeBatch(1, 4);
  m.header.run_id = 42;
  m.header.utime = WallMicros();
  for (const std::string& sender : {std::string(kMaxSenderBytes + 1, 'a'), std::string("a b")}) {
    m.header.sender = sender;
    std::vector<uint8_t> bytes(static_cast<size_t>(m.getEncodedSize()));
    m.encode(bytes.data(), 0, static_cast<int>(bytes.size()));
    bus.Deliver(channels::kTransitions, bytes.data(), bytes.size(), m.header.utime);
  }
  EXPECT_EQ(got, 0);
  EXPECT_EQ(bus.counters().malformed, 2);
}

// The table of common/channels.h: every type of lcmtypes/ but header_t once, each on a channel of
// its own; the example of each passes Validate() and reaches a subscriber of its channel (so the
// publisher and the subscriber chose the same port), in the table's order.
TEST(MessageTableTest, ListsEveryTypeOnceAndEachExampleCrossesTheBus) {
  std::set<std::string_view> types, names;
  for (const MessageInfo& m : kMessages) {
    types.insert(m.type);
    names.insert(m.channel);
  }
  EXPECT_EQ(types.size(), kNumMessages);
  EXPECT_EQ(names.size(), kNumMessages);
  EXPECT_EQ(LcmSchemas().size(), kNumMessages + 1) << "a .lcm file without a line in the table";
  EXPECT_EQ(MessageIndex("header_t"), -1);

  Bus bus(MemqConfig(5, "test"));
  std::vector<std::string> got;
  int index = 0;
#define RL_CHECK_LINE(type, constant, name, on_port)                                         \
  EXPECT_EQ(MessageIndex(rlmsg::type::getTypeName()), index++);                              \
  EXPECT_EQ(FindChannel(channels::constant)->port, Port::on_port);                           \
  bus.Subscribe<rlmsg::type>(name, [&got](const rlmsg::type&) { got.emplace_back(#type); }); \
  {                                                                                          \
    rlmsg::type m = examples::Example<rlmsg::type>();                                        \
    EXPECT_EQ(Validate(m), nullptr) << #type;                                                \
    EXPECT_TRUE(bus.Publish(name, &m));                                                      \
  }
  RL_MESSAGES(RL_CHECK_LINE)
#undef RL_CHECK_LINE
  for (int i = 0; i < 100 && got.size() < kNumMessages; ++i) bus.Handle(10);
  ASSERT_EQ(got.size(), kNumMessages) << "some example was dropped or went on another port";
  EXPECT_EQ(bus.counters().dropped(), 0);
}

// A channel of the table takes only its type, on its port; other channels take any.
TEST(MessageTableTest, RefusesAnotherTypeOrPortOnAChannelOfTheTable) {
  Bus bus(MemqConfig(5, "test"));
  EXPECT_THROW(
      bus.Subscribe<rlmsg::checkpoint_t>(channels::kTransitions, [](const rlmsg::checkpoint_t&) {}),
      std::invalid_argument);
  rlmsg::checkpoint_t c = examples::Example<rlmsg::checkpoint_t>();
  EXPECT_THROW(bus.Publish(channels::kWeights, &c), std::invalid_argument);
  rlmsg::weights_chunk_t w = examples::Example<rlmsg::weights_chunk_t>();
  EXPECT_THROW(bus.Publish(channels::kWeights, &w, Port::kMain), std::invalid_argument);
  EXPECT_EQ(ChannelPort(channels::kWeights, "weights_chunk_t", std::nullopt), Port::kBulk);
  EXPECT_EQ(ChannelPort(channels::kWeights, "", std::nullopt), Port::kBulk);
  EXPECT_EQ(ChannelPort(channels::kSamples, "sample_batch_t", std::nullopt), Port::kSamples);
  try {
    ChannelPort(channels::kSamples, "sample_batch_t", Port::kBulk);
    ADD_FAILURE() << "a sample reply was let onto the bulk port";
  } catch (const std::invalid_argument& e) {
    EXPECT_STREQ(e.what(), "RL_SAMPLES goes on the samples port (common/channels.h)");
  }
  EXPECT_EQ(ChannelPort("TEST_CHANNEL", "checkpoint_t", std::nullopt), Port::kMain);
  EXPECT_EQ(ChannelPort("TEST_CHANNEL", "checkpoint_t", Port::kBulk), Port::kBulk);
  EXPECT_TRUE(bus.Publish("TEST_CHANNEL", &c));
}

// A bus binds (and joins the multicast group of) only the ports it subscribes on, when it handles
// traffic: a process with no use for the bulk port (the monitor, the evaluator, the replay, which
// only publishes there) must not receive the run's weights only to drop them, and one with no
// use for the samples port (the actors, which listen for weights) the sample replies.
TEST(BusPortsTest, HandleBindsOnlyThePortsWithASubscription) {
  const int port = PickRunPorts(10);
  if (port == 0) GTEST_SKIP() << "ports in use";
  BusConfig c = MemqConfig(5, "monitor");
  c.url = "udpm://239.255.76.67:" + std::to_string(port) + "?ttl=0";
  c.bulk_url = "udpm://239.255.76.67:" + std::to_string(port + 1) + "?ttl=0";
  c.samples_url = "udpm://239.255.76.67:" + std::to_string(port + 2) + "?ttl=0";
  std::unique_ptr<Bus> bus;
  try {
    bus = std::make_unique<Bus>(c);
  } catch (const std::runtime_error& e) {
    GTEST_SKIP() << "no multicast here: " << e.what();
  }
  bus->Subscribe<rlmsg::stats_actor_t>(channels::kStatsActor, [](const rlmsg::stats_actor_t&) {});
  // LCM closes a port it cannot hear its own test message on (multicast loopback blocked).
  if (OwnSocketsOnPort("udp", port) == 0) GTEST_SKIP() << "LCM cannot receive multicast here";
  bus->Handle(0);
  EXPECT_EQ(OwnSocketsOnPort("udp", port), 1);
  EXPECT_EQ(OwnSocketsOnPort("udp", port + 1), 0)
      << "the bulk port was bound without a subscription";

  // Subscribed there too, it hears what is published there.
  int weights = 0;
  bus->Subscribe<rlmsg::weights_chunk_t>(
      channels::kWeights, [&weights](const rlmsg::weights_chunk_t&) { ++weights; }, Port::kBulk);
  EXPECT_EQ(OwnSocketsOnPort("udp", port + 1), 1);
  rlmsg::weights_chunk_t w = examples::Example<rlmsg::weights_chunk_t>();
  ASSERT_TRUE(bus->Publish(channels::kWeights, &w));
  for (int i = 0; i < 100 && weights == 0; ++i) bus->Handle(10);
  EXPECT_EQ(weights, 1);
  EXPECT_EQ(OwnSocketsOnPort("udp", port + 2), 0)
      << "the samples port was bound without a subscription";

  // And the same for the samples port: subscribed, it is bound and hears the replies, which no
  // longer reach the bulk port's subscribers.
  int replies = 0;
  bus->Subscribe<rlmsg::sample_batch_t>(channels::kSamples,
                                        [&replies](const rlmsg::sample_batch_t&) { ++replies; });
  bus->Handle(0);
  EXPECT_EQ(OwnSocketsOnPort("udp", port + 2), 1);
  rlmsg::sample_batch_t s = examples::Example<rlmsg::sample_batch_t>();
  ASSERT_TRUE(bus->Publish(channels::kSamples, &s));
  for (int i = 0; i < 100 && replies == 0; ++i) bus->Handle(10);
  EXPECT_EQ(replies, 1);
  EXPECT_EQ(weights, 1);
}

// A samples URL equal to the bulk one (a run through TCP hubs) shares the bulk port's LCM
// instance: one socket, and the replies are heard there.
TEST(BusPortsTest, TheSamplesPortCanShareTheBulkPort) {
  const int port = PickRunPorts(10);
  if (port == 0) GTEST_SKIP() << "ports in use";
  BusConfig c = MemqConfig(5, "learner");
  c.url = "udpm://239.255.76.67:" + std::to_string(port) + "?ttl=0";
  c.bulk_url = c.samples_url = "udpm://239.255.76.67:" + std::to_string(port + 1) + "?ttl=0";
  std::unique_ptr<Bus> bus;
  try {
    bus = std::make_unique<Bus>(c);
  } catch (const std::runtime_error& e) {
    GTEST_SKIP() << "no multicast here: " << e.what();
  }
  int replies = 0, weights = 0;
  bus->Subscribe<rlmsg::sample_batch_t>(channels::kSamples,
                                        [&replies](const rlmsg::sample_batch_t&) { ++replies; });
  bus->Subscribe<rlmsg::weights_chunk_t>(channels::kWeights,
                                         [&weights](const rlmsg::weights_chunk_t&) { ++weights; });
  bus->Handle(0);
  if (OwnSocketsOnPort("udp", port + 1) == 0) GTEST_SKIP() << "LCM cannot receive multicast here";
  EXPECT_EQ(OwnSocketsOnPort("udp", port + 1), 1) << "two sockets on the shared port";
  EXPECT_EQ(OwnSocketsOnPort("udp", port + 2), 0);
  rlmsg::sample_batch_t s = examples::Example<rlmsg::sample_batch_t>();
  rlmsg::weights_chunk_t w = examples::Example<rlmsg::weights_chunk_t>();
  ASSERT_TRUE(bus->Publish(channels::kSamples, &s));
  ASSERT_TRUE(bus->Publish(channels::kWeights, &w));
  for (int i = 0; i < 100 && (replies == 0 || weights == 0); ++i) bus->Handle(10);
  EXPECT_EQ(replies, 1);
  EXPECT_EQ(weights, 1);
}

// A udpm port another program holds (a UDP socket bound without SO_REUSEADDR, as a sending
// socket given that ephemeral port is) cannot be bound by LCM: subscribing there is a clear
// error, not a crash (LCM's C++ API hands back a subscription it never made).
TEST(BusPortsTest, APortHeldByAnotherProgramIsAClearErrorAtSubscription) {
  const int fd = socket(AF_INET, SOCK_DGRAM, 0);
  ASSERT_GE(fd, 0);
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  socklen_t size = sizeof(addr);
  ASSERT_EQ(bind(fd, reinterpret_cast<sockaddr*>(&addr), size), 0);
  ASSERT_EQ(getsockname(fd, reinterpret_cast<sockaddr*>(&addr), &size), 0);
  const int held = ntohs(addr.sin_port);
  BusConfig c = MemqConfig(5, "actor-0");
  c.bulk_url = "udpm://239.255.76.67:" + std::to_string(held) + "?ttl=0";
  std::unique_ptr<Bus> bus;
  try {
    bus = std::make_unique<Bus>(c);
  } catch (const std::runtime_error& e) {
    close(fd);
    GTEST_SKIP() << "no multicast here: " << e.what();
  }
  try {
    bus->Subscribe<rlmsg::weights_chunk_t>(
        channels::kWeights, [](const rlmsg::weights_chunk_t&) {}, Port::kBulk);
    ADD_FAILURE() << "subscribed on a port another socket holds";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("on the bulk port (" + c.bulk_url + ")"),
              std::string::npos)
        << e.what();
  }
  // The ports that could bind still work.
  int stats = 0;
  bus->Subscribe<rlmsg::stats_actor_t>(channels::kStatsActor,
                                       [&stats](const rlmsg::stats_actor_t&) { ++stats; });
  rlmsg::stats_actor_t s = examples::Example<rlmsg::stats_actor_t>();
  ASSERT_TRUE(bus->Publish(channels::kStatsActor, &s));
  for (int i = 0; i < 100 && stats == 0; ++i) bus->Handle(10);
  EXPECT_EQ(stats, 1);
  close(fd);
}

}  // namespace
}  // namespace rl
