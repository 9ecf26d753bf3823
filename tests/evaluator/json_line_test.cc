#include "evaluator/json_line.h"

#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include <gtest/gtest.h>

namespace rl {
namespace {

TEST(JsonLineTest, ReadsStringsNumbersBooleansAndNull) {
  const std::optional<nlohmann::json> obj = ParseJsonLine(
      R"( {"s": "a\"b\\c\n\u00e9\ud83d\ude00", "n": -1.5e3, "t": true, "f": false, "z": null} )");
  ASSERT_TRUE(obj.has_value());
  EXPECT_EQ(JsonStringAt(*obj, "s"), "a\"b\\c\n\xC3\xA9\xF0\x9F\x98\x80");
  EXPECT_EQ(JsonNumberAt(*obj, "n"), -1500.0);
  EXPECT_EQ(JsonIntegerAt(*obj, "n"), -1500);
  EXPECT_EQ(JsonIntegerAt(*obj, "t"), 1);
  EXPECT_EQ(JsonIntegerAt(*obj, "f"), 0);
  EXPECT_TRUE(std::isnan(JsonNumberAt(*obj, "z").value()));
  EXPECT_FALSE(JsonIntegerAt(*obj, "z").has_value());
  EXPECT_FALSE(JsonNumberAt(*obj, "s").has_value());
  EXPECT_FALSE(JsonStringAt(*obj, "n").has_value());
  EXPECT_FALSE(JsonNumberAt(*obj, "missing").has_value());
  // A whole number written as a double is an integer; a fraction or a huge one is not.
  const std::optional<nlohmann::json> numbers =
      ParseJsonLine(R"({"a": 1e6, "b": 2.5, "c": 1e300, "d": 18446744073709551615})");
  ASSERT_TRUE(numbers.has_value());
  EXPECT_EQ(JsonIntegerAt(*numbers, "a"), 1000000);
  EXPECT_FALSE(JsonIntegerAt(*numbers, "b").has_value());
  EXPECT_FALSE(JsonIntegerAt(*numbers, "c").has_value());
  EXPECT_FALSE(JsonIntegerAt(*numbers, "d").has_value());
}

TEST(JsonLineTest, ReadsArraysOfNumbersAndRefusesOtherArrays) {
  const std::optional<nlohmann::json> obj =
      ParseJsonLine(R"({"a": [1, -2.5, null], "e": [], "s": [1, "x"], "n": 3, "o": [[1]]})");
  ASSERT_TRUE(obj.has_value());
  const std::optional<std::vector<double>> a = JsonNumbersAt(*obj, "a");
  ASSERT_TRUE(a.has_value());
  ASSERT_EQ(a->size(), 3U);
  EXPECT_EQ((*a)[0], 1.0);
  EXPECT_EQ((*a)[1], -2.5);
  EXPECT_TRUE(std::isnan((*a)[2]));
  EXPECT_EQ(JsonNumbersAt(*obj, "e"), std::vector<double>{});
  for (const char* key : {"s", "n", "o", "missing"}) {
    EXPECT_FALSE(JsonNumbersAt(*obj, key).has_value()) << key;
  }
}

TEST(JsonLineTest, RejectsTornAndMalformedLinesAndOtherValues) {
  EXPECT_FALSE(ParseJsonLine(R"({"a": 1} x)").has_value());   // trailing text
  EXPECT_FALSE(ParseJsonLine(R"({"a": "\q"})").has_value());  // bad escape
  EXPECT_FALSE(ParseJsonLine(R"({"a": 1,})").has_value());
  EXPECT_FALSE(ParseJsonLine(R"({"a" 1})").has_value());
  EXPECT_FALSE(ParseJsonLine("{\"a\": \"x\ny\"}").has_value());  // raw control character
  EXPECT_FALSE(ParseJsonLine(R"({"checkpoint": "c.bin", "upd)").has_value());  // torn
  EXPECT_FALSE(ParseJsonLine("").has_value());
  EXPECT_FALSE(ParseJsonLine("[1, 2]").has_value());  // not an object
  EXPECT_FALSE(ParseJsonLine("\"text\"").has_value());
  EXPECT_TRUE(ParseJsonLine("{}").has_value());
}

TEST(JsonLineTest, NumbersReadBackExactlyAndNonFiniteBecomesNull) {
  for (double v : {0.1, 1.0 / 3.0, -2.5e-300, 475.0, 1e17}) {
    nlohmann::ordered_json j;
    j["v"] = v;
    const std::optional<nlohmann::json> back = ParseJsonLine(JsonLine(j));
    ASSERT_TRUE(back.has_value()) << JsonLine(j);
    EXPECT_EQ(JsonNumberAt(*back, "v"), v);
  }
  nlohmann::ordered_json j;
  j["inf"] = std::numeric_limits<double>::infinity();
  j["nan"] = std::nan("");
  EXPECT_EQ(JsonLine(j), R"({"inf": null, "nan": null})");
}

TEST(JsonLineTest, WritesTheMembersInOrderWithASpaceAfterColonsAndCommas) {
  nlohmann::ordered_json j;
  j["t"] = 12.5;
  j["role"] = "tab\there \x01";
  j["n"] = int64_t{5000};
  j["bad"] = "\xFF";  // not UTF-8: replaced, not thrown
  EXPECT_EQ(JsonLine(j),
            "{\"t\": 12.5, \"role\": \"tab\\there \\u0001\", \"n\": 5000, "
            "\"bad\": \"\xEF\xBF\xBD\"}");
  EXPECT_THROW(JsonLine(nlohmann::ordered_json::array()), std::invalid_argument);
}

}  // namespace
}  // namespace rl
