#include "common/text_format.h"

#include <cmath>
#include <cstdio>
#include <ctime>

namespace rl {

std::string FormatDouble(const char* fmt, double v) {
  char buf[64];
  std::snprintf(buf, sizeof(buf), fmt, v);
  return buf;
}

std::string Score(double v) {
  const bool small = std::fabs(v) < 10;
  const double scale = small ? 100 : 10;
  // Rounded down, so that a score never reads as reaching a goal it missed (899.96 is not "900.0");
  // the small margin keeps a value that is a hair under its decimal (475 computed as 474.99999...)
  // from losing a digit.
  if (std::isfinite(v)) v = std::floor(v * scale + 1e-6) / scale;
  return FormatDouble(small ? "%.2f" : "%.1f", v);
}

std::string Thousands(int64_t v) {
  const std::string digits = std::to_string(v < 0 ? -v : v);
  std::string out;
  for (size_t i = 0; i < digits.size(); ++i) {
    if (i > 0 && (digits.size() - i) % 3 == 0) out += ',';
    out += digits[i];
  }
  return v < 0 ? "-" + out : out;
}

std::string UtcNow() {
  const std::time_t now = std::time(nullptr);
  std::tm tm{};
  gmtime_r(&now, &tm);
  char buf[64];
  std::strftime(buf, sizeof(buf), "%Y-%m-%d %H:%M:%S UTC", &tm);
  return buf;
}

std::string Duration(double seconds, const char* missing) {
  if (!std::isfinite(seconds) || seconds < 0) return missing;
  if (seconds < 60) return FormatDouble(seconds < 10 ? "%.1f s" : "%.0f s", seconds);
  const auto total = static_cast<long long>(std::llround(seconds));
  char buf[64];
  if (total < 3600) {
    std::snprintf(buf, sizeof(buf), "%lld min %02lld s", total / 60, total % 60);
  } else {
    std::snprintf(buf, sizeof(buf), "%lld h %02lld min", total / 3600, (total % 3600) / 60);
  }
  return buf;
}

}  // namespace rl
