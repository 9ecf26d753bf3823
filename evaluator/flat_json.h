// Just enough JSON for eval.jsonl: writing strings and numbers, and reading one flat object whose
// values are strings, numbers, booleans or null (no nested objects or arrays).
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <string_view>

namespace rl::evaluator {

/// A value of a flat JSON object: a decoded string, or a number's text ("1" and "0" for true and
/// false), or null.
struct JsonValue {
  bool is_string = false;
  bool is_null = false;
  std::string text;
};

using JsonObject = std::map<std::string, JsonValue>;

/// Parses `text` as one flat JSON object (surrounding whitespace allowed). Returns false, leaving
/// *out partly filled, for anything else, including nested values and trailing text.
bool ParseFlatJsonObject(std::string_view text, JsonObject* out);

/// Appends `text` as a JSON string literal (quotes, backslashes and control characters escaped;
/// other bytes, UTF-8 included, as they are).
void AppendJsonString(std::string* out, const std::string& text);

/// The shortest text that reads back as exactly `v`; "null" when `v` is not finite (JSON has
/// no NaN or infinity).
std::string JsonNumber(double v);

/// The number under `key`: NaN for null, nullopt when missing, a string or not a number.
std::optional<double> GetJsonDouble(const JsonObject& obj, const char* key);

/// The whole number under `key` (also written as a double, e.g. 1e6); nullopt when missing,
/// null, a string or not a whole number.
std::optional<int64_t> GetJsonInt(const JsonObject& obj, const char* key);

}  // namespace rl::evaluator
