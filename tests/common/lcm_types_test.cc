// Every message type of lcmtypes/, decoded into a reused object as the bus decodes a
// subscription's messages: arrays of N elements, then of none, must leave the object equal to a
// fresh decode of the second message (allocation_test.cc: and allocate nothing once warm).
//
// The messages are written from the .lcm schemas (tests/common/schema_message.h), so a new type
// or field is covered without a change here; the objects are compared field by field through
// structured bindings (the generated classes are aggregates), so is a new field.
#include <cctype>
#include <cstdint>
#include <cstring>
#include <functional>
#include <limits>
#include <map>
#include <string>
#include <tuple>
#include <type_traits>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "common/channels.h"
#include "common/lcm_bus.h"
#include "common/lcm_schema.h"
#include "common/messages.h"
#include "rlmsg/all_types.hpp"
#include "tests/common/schema_message.h"

namespace rl {
namespace {

// --- Field-by-field comparison ------------------------------------------------------------

// Converts to any field type; only used unevaluated, to count an aggregate's fields.
struct AnyField {
  template <class T>
  operator T() const;  // NOLINT(google-explicit-constructor)
};
template <size_t>
using Any = AnyField;

template <class T, size_t... I>
constexpr bool BracedFrom(std::index_sequence<I...>) {
  return requires { T{Any<I>{}...}; };
}
// The number of fields of an aggregate without C arrays (their elements would count one by one).
template <class T, size_t N = 0>
constexpr size_t FieldCount() {
  if constexpr (BracedFrom<T>(std::make_index_sequence<N + 1>{})) {
    return FieldCount<T, N + 1>();
  } else {
    return N;
  }
}

#define RL_TIE(n, ...)            \
  if constexpr (kFields == n) {   \
    auto& [__VA_ARGS__] = object; \
    return std::tie(__VA_ARGS__); \
  } else

// References to every field of a message object, in declaration order.
template <class T>
auto Tie(const T& object) {
  constexpr size_t kFields = FieldCount<T>();
  static_assert(kFields >= 1 && kFields <= 32, "extend Tie() to this many fields");
  RL_TIE(1, a)
  RL_TIE(2, a, b)
  RL_TIE(3, a, b, c)
  RL_TIE(4, a, b, c, d)
  RL_TIE(5, a, b, c, d, e)
  RL_TIE(6, a, b, c, d, e, f)
  RL_TIE(7, a, b, c, d, e, f, g)
  RL_TIE(8, a, b, c, d, e, f, g, h)
  RL_TIE(9, a, b, c, d, e, f, g, h, i)
  RL_TIE(10, a, b, c, d, e, f, g, h, i, j)
  RL_TIE(11, a, b, c, d, e, f, g, h, i, j, k)
  RL_TIE(12, a, b, c, d, e, f, g, h, i, j, k, l)
  RL_TIE(13, a, b, c, d, e, f, g, h, i, j, k, l, m)
  RL_TIE(14, a, b, c, d, e, f, g, h, i, j, k, l, m, n)
  RL_TIE(15, a, b, c, d, e, f, g, h, i, j, k, l, m, n, o)
  RL_TIE(16, a, b, c, d, e, f, g, h, i, j, k, l, m, n, o, p)
  RL_TIE(17, a, b, c, d, e, f, g, h, i, j, k, l, m, n, o, p, q)
  RL_TIE(18, a, b, c, d, e, f, g, h, i, j, k, l, m, n, o, p, q, r)
  RL_TIE(19, a, b, c, d, e, f, g, h, i, j, k, l, m, n, o, p, q, r, s)
  RL_TIE(20, a, b, c, d, e, f, g, h, i, j, k, l, m, n, o, p, q, r, s, t)
  RL_TIE(21, a, b, c, d, e, f, g, h, i, j, k, l, m, n, o, p, q, r, s, t, u)
  RL_TIE(22, a, b, c, d, e, f, g, h, i, j, k, l, m, n, o, p, q, r, s, t, u, v)
  RL_TIE(23, a, b, c, d, e, f, g, h, i, j, k, l, m, n, o, p, q, r, s, t, u, v, w)
  RL_TIE(24, a, b, c, d, e, f, g, h, i, j, k, l, m, n, o, p, q, r, s, t, u, v, w, x)
  RL_TIE(25, a, b, c, d, e, f, g, h, i, j, k, l, m, n, o, p, q, r, s, t, u, v, w, x, y)
  RL_TIE(26, a, b, c, d, e, f, g, h, i, j, k, l, m, n, o, p, q, r, s, t, u, v, w, x, y, z)
  RL_TIE(27, a, b, c, d, e, f, g, h, i, j, k, l, m, n, o, p, q, r, s, t, u, v, w, x, y, z, a1)
  RL_TIE(28, a, b, c, d, e, f, g, h, i, j, k, l, m, n, o, p, q, r, s, t, u, v, w, x, y, z, a1, b1)
  RL_TIE(29, a, b, c, d, e, f, g, h, i, j, k, l, m, n, o, p, q, r, s, t, u, v, w, x, y, z, a1, b1,
         c1)
  RL_TIE(30, a, b, c, d, e, f, g, h, i, j, k, l, m, n, o, p, q, r, s, t, u, v, w, x, y, z, a1, b1,
         c1, d1)
  RL_TIE(31, a, b, c, d, e, f, g, h, i, j, k, l, m, n, o, p, q, r, s, t, u, v, w, x, y, z, a1, b1,
         c1, d1, e1)
  RL_TIE(32, a, b, c, d, e, f, g, h, i, j, k, l, m, n, o, p, q, r, s, t, u, v, w, x, y, z, a1, b1,
         c1, d1, e1, f1) {
    return std::tuple<>();
  }
}
#undef RL_TIE

template <class T>
struct IsVector : std::false_type {};
template <class T>
struct IsVector<std::vector<T>> : std::true_type {};

// Whether two fields are equal, and if not, which (appended to *where).
template <class T>
bool Equal(const T& a, const T& b, std::string* where);

bool Equal(const rlmsg::header_t& a, const rlmsg::header_t& b, std::string* where) {
  // header_t holds a C array, which FieldCount() cannot count: its fields by name.
  const bool same = a.run_id == b.run_id && a.sender == b.sender && a.seq == b.seq &&
                    a.utime == b.utime && a.incarnation == b.incarnation &&
                    std::memcmp(a.mac, b.mac, sizeof(a.mac)) == 0;
  if (!same) *where += " header";
  return same;
}

template <class T>
bool Equal(const T& a, const T& b, std::string* where) {
  if constexpr (std::is_arithmetic_v<T> || std::is_same_v<T, std::string>) {
    return a == b;
  } else if constexpr (IsVector<T>::value) {
    if (a.size() != b.size()) {
      *where += ": " + std::to_string(a.size()) + " elements, not " + std::to_string(b.size());
      return false;
    }
    for (size_t i = 0; i < a.size(); ++i) {
      if (!Equal(a[i], b[i], where)) return false;
    }
    return true;
  } else {
    const auto fa = Tie(a);
    const auto fb = Tie(b);
    return [&]<size_t... I>(std::index_sequence<I...>) {
      bool same = true;
      std::string inner;
      ((Equal(std::get<I>(fa), std::get<I>(fb), &inner) ||
        (same = false, *where += " field " + std::to_string(I) + inner, inner.clear(), false)),
       ...);
      return same;
    }
    (std::make_index_sequence<std::tuple_size_v<decltype(fa)>>{});
  }
}

// --- The tests ----------------------------------------------------------------------------

// For every type: the fields FieldCount() sees are the schema's (so the comparison covers every
// field), and decoding arrays of N, then of none, into one object leaves it equal to a fresh
// decode of the second message.
template <class Msg>
void CheckShrinkToZero() {
  const std::string type = Msg::getTypeName();
  SCOPED_TRACE(type);
  const LcmStruct& schema = LcmSchemas().at(type);
  if (type != "header_t") {
    ASSERT_EQ(FieldCount<Msg>(), schema.fields.size()) << "fields seen by the comparison";
  }
  for (const int64_t n : {1, 5}) {
    const auto full = SchemaMessage(type, Msg::getHash(), n, /*salt=*/0);
    const auto empty = SchemaMessage(type, Msg::getHash(), 0, /*salt=*/50);
    Msg reused{}, fresh{};
    ASSERT_EQ(Decode(full.data(), full.size(), &reused), nullptr);
    ASSERT_EQ(Decode(empty.data(), empty.size(), &reused), nullptr);
    ASSERT_EQ(Decode(empty.data(), empty.size(), &fresh), nullptr);
    std::string where;
    EXPECT_TRUE(Equal(reused, fresh, &where)) << "arrays of " << n << " then 0:" << where;
    // And back: the regrown object equals a fresh decode of the full message.
    ASSERT_EQ(Decode(full.data(), full.size(), &reused), nullptr);
    Msg fresh_full{};
    ASSERT_EQ(Decode(full.data(), full.size(), &fresh_full), nullptr);
    where.clear();
    EXPECT_TRUE(Equal(reused, fresh_full, &where)) << "regrown to " << n << ":" << where;
  }
}

TEST(LcmTypesTest, EveryTypeDecodedIntoAReusedObjectEqualsAFreshDecode) {
  size_t types = 0;
#define RL_CHECK_TYPE(type)         \
  CheckShrinkToZero<rlmsg::type>(); \
  ++types;
  RLMSG_ALL_TYPES(RL_CHECK_TYPE)
#undef RL_CHECK_TYPE
  EXPECT_EQ(types, LcmSchemas().size()) << "every .lcm file of lcmtypes/ is a type checked here";
}

// The case that stalled runs: the replay, restarted with no actors known, sends flow control
// with num_actors 0 after messages that listed actors; every one must reach the handler with
// empty arrays (it was dropped as "num_actors mismatch").
TEST(LcmTypesTest, FlowControlWithNoActorsAfterSomeReachesTheHandler) {
  Bus replay(InProcessBusConfig(7, "replay"));
  Bus actor(InProcessBusConfig(7, "actor-0"));
  std::vector<size_t> actor_ids;
  actor.Subscribe<rlmsg::flow_control_t>(channels::kFlow, [&](const rlmsg::flow_control_t& m) {
    actor_ids.push_back(m.actor_id.size());
  });
  for (const int actors : {3, 0, 2, 0}) {
    rlmsg::flow_control_t m{};
    m.insert_allowed = 1;
    m.num_actors = actors;
    for (int a = 0; a < actors; ++a) {
      m.actor_id.push_back(a);
      m.actor_inserts.push_back(100);
    }
    ASSERT_TRUE(replay.Publish(channels::kFlow, &m));
    std::vector<uint8_t> bytes(static_cast<size_t>(m.getEncodedSize()));
    ASSERT_EQ(m.encode(bytes.data(), 0, static_cast<int>(bytes.size())),
              static_cast<int>(bytes.size()));
    actor.Deliver(channels::kFlow, bytes.data(), bytes.size(), m.header.utime);
  }
  EXPECT_EQ(actor_ids, (std::vector<size_t>{3, 0, 2, 0}));
  EXPECT_EQ(actor.counters().invalid, 0);
}

}  // namespace
}  // namespace rl
