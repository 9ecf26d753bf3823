// JSON lines (eval.jsonl, metrics.jsonl) through nlohmann-json: one flat object per line, written
// as {"key": value, "key": value} (a space after every colon and comma, as the files' readers and
// the scripts that grep them expect), read back by nlohmann's parser with typed getters that
// never throw.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

namespace rl {

/// One line (without its newline) of `object`'s members in their order. Strings are escaped by
/// nlohmann-json (bytes that are not UTF-8 become U+FFFD); numbers take their shortest form that
/// reads back exactly (a double that is whole keeps a ".0"); a NaN or infinity is written as
/// null (JSON has neither). Throws std::invalid_argument when `object` is not an object.
std::string JsonLine(const nlohmann::ordered_json& object);

/// Parses one line as a JSON object (surrounding whitespace allowed). nullopt for anything else:
/// malformed or torn text, trailing text, or a value that is not an object. Never throws.
std::optional<nlohmann::json> ParseJsonLine(std::string_view line);

/// The number under `key` of `object`: NaN for null, 1 or 0 for true or false; nullopt when it
/// is missing or not a number.
std::optional<double> JsonNumberAt(const nlohmann::json& object, const char* key);

/// The whole number under `key` (also one written as a double, e.g. 1e6); nullopt when it is
/// missing, null, not a number, not whole or beyond int64.
std::optional<int64_t> JsonIntegerAt(const nlohmann::json& object, const char* key);

/// The array of numbers under `key` (null elements as NaN); nullopt when it is missing, not an
/// array or holds anything but numbers and nulls.
std::optional<std::vector<double>> JsonNumbersAt(const nlohmann::json& object, const char* key);

/// The string under `key`; nullopt when it is missing or not a string.
std::optional<std::string> JsonStringAt(const nlohmann::json& object, const char* key);

}  // namespace rl
