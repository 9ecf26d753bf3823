#include "evaluator/flat_json.h"

#include <cmath>
#include <limits>
#include <string>

#include <gtest/gtest.h>

namespace rl::evaluator {
namespace {

TEST(FlatJsonTest, ReadsStringsNumbersBooleansAndNull) {
  JsonObject obj;
  ASSERT_TRUE(ParseFlatJsonObject(
      R"( {"s": "a\"b\\c\n\u00e9\ud83d\ude00", "n": -1.5e3, "t": true, "f": false, "z": null} )",
      &obj));
  EXPECT_EQ(obj["s"].text, "a\"b\\c\n\xC3\xA9\xF0\x9F\x98\x80");
  EXPECT_TRUE(obj["s"].is_string);
  EXPECT_EQ(GetJsonDouble(obj, "n"), -1500.0);
  EXPECT_EQ(GetJsonInt(obj, "n"), -1500);
  EXPECT_EQ(GetJsonInt(obj, "t"), 1);
  EXPECT_EQ(GetJsonInt(obj, "f"), 0);
  EXPECT_TRUE(std::isnan(GetJsonDouble(obj, "z").value()));
  EXPECT_FALSE(GetJsonInt(obj, "z").has_value());
  EXPECT_FALSE(GetJsonDouble(obj, "s").has_value());
  EXPECT_FALSE(GetJsonDouble(obj, "missing").has_value());
}

TEST(FlatJsonTest, RejectsNestedValuesTrailingTextAndBadEscapes) {
  JsonObject obj;
  EXPECT_FALSE(ParseFlatJsonObject(R"({"a": [1]})", &obj));
  EXPECT_FALSE(ParseFlatJsonObject(R"({"a": {"b": 1}})", &obj));
  EXPECT_FALSE(ParseFlatJsonObject(R"({"a": 1} x)", &obj));
  EXPECT_FALSE(ParseFlatJsonObject(R"({"a": "\q"})", &obj));
  EXPECT_FALSE(ParseFlatJsonObject(R"({"a": 1,})", &obj));
  EXPECT_FALSE(ParseFlatJsonObject(R"({"a" 1})", &obj));
  EXPECT_FALSE(ParseFlatJsonObject("{\"a\": \"x\ny\"}", &obj));  // raw control character
  EXPECT_TRUE(ParseFlatJsonObject("{}", &obj));
}

TEST(FlatJsonTest, NumbersReadBackExactlyAndNonFiniteBecomesNull) {
  for (double v : {0.1, 1.0 / 3.0, -2.5e-300, 475.0, 1e17}) {
    JsonObject obj;
    ASSERT_TRUE(ParseFlatJsonObject("{\"v\": " + JsonNumber(v) + "}", &obj));
    EXPECT_EQ(GetJsonDouble(obj, "v"), v);
  }
  EXPECT_EQ(JsonNumber(std::numeric_limits<double>::infinity()), "null");
  EXPECT_EQ(JsonNumber(std::nan("")), "null");
  std::string s;
  AppendJsonString(&s, "tab\there \x01");
  EXPECT_EQ(s, "\"tab\\there \\u0001\"");
}

}  // namespace
}  // namespace rl::evaluator
