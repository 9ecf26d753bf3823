#include "evaluator/json_line.h"

#include <cmath>
#include <limits>
#include <stdexcept>

namespace rl {
namespace {

std::string Dump(const nlohmann::ordered_json& value) {
  return value.dump(-1, ' ', false, nlohmann::ordered_json::error_handler_t::replace);
}

}  // namespace

std::string JsonLine(const nlohmann::ordered_json& object) {
  if (!object.is_object()) throw std::invalid_argument("a JSON line holds an object");
  // nlohmann's compact form has no spaces ({"a":1}); the files keep {"a": 1}.
  std::string line = "{";
  for (auto it = object.begin(); it != object.end(); ++it) {
    if (it != object.begin()) line += ", ";
    line += Dump(it.key()) + ": " + Dump(it.value());
  }
  return line + "}";
}

std::optional<nlohmann::json> ParseJsonLine(std::string_view line) {
  nlohmann::json value = nlohmann::json::parse(line, nullptr, /*allow_exceptions=*/false);
  if (!value.is_object()) return std::nullopt;  // discarded (malformed) or not an object
  return value;
}

std::optional<double> JsonNumberAt(const nlohmann::json& object, const char* key) {
  const auto it = object.find(key);
  if (it == object.end()) return std::nullopt;
  if (it->is_null()) return std::nan("");
  if (it->is_boolean()) return it->get<bool>() ? 1.0 : 0.0;
  if (!it->is_number()) return std::nullopt;
  return it->get<double>();
}

std::optional<int64_t> JsonIntegerAt(const nlohmann::json& object, const char* key) {
  const auto it = object.find(key);
  if (it == object.end()) return std::nullopt;
  if (it->is_boolean()) return it->get<bool>() ? 1 : 0;
  if (it->is_number_integer() && !it->is_number_unsigned()) return it->get<int64_t>();
  if (it->is_number_unsigned()) {
    const auto v = it->get<uint64_t>();
    if (v > static_cast<uint64_t>(std::numeric_limits<int64_t>::max())) return std::nullopt;
    return static_cast<int64_t>(v);
  }
  if (!it->is_number_float()) return std::nullopt;
  const double d = it->get<double>();
  if (!std::isfinite(d) || d != std::round(d) || std::abs(d) >= 9e18) return std::nullopt;
  return static_cast<int64_t>(d);
}

std::optional<std::vector<double>> JsonNumbersAt(const nlohmann::json& object, const char* key) {
  const auto it = object.find(key);
  if (it == object.end() || !it->is_array()) return std::nullopt;
  std::vector<double> numbers;
  numbers.reserve(it->size());
  for (const nlohmann::json& element : *it) {
    if (element.is_null()) {
      numbers.push_back(std::nan(""));
    } else if (element.is_number()) {
      numbers.push_back(element.get<double>());
    } else {
      return std::nullopt;
    }
  }
  return numbers;
}

std::optional<std::string> JsonStringAt(const nlohmann::json& object, const char* key) {
  const auto it = object.find(key);
  if (it == object.end() || !it->is_string()) return std::nullopt;
  return it->get<std::string>();
}

}  // namespace rl
