// Numbers as people read them, the same on the progress line, in the report and on the compare
// page: scores, counts with thousands separators, durations.
#pragma once

#include <cstdint>
#include <string>

namespace rl {

/// printf of one double with `fmt` (at most 63 characters of output).
std::string FormatDouble(const char* fmt, double v);

/// A return or a rate: two decimals below 10 in magnitude (grasp success 0.35), else one; rounded
/// down, so that a mean below a goal never shows as the goal (899.96 -> "899.9").
std::string Score(double v);

/// 1234567 -> "1,234,567" (negative values keep their sign).
std::string Thousands(int64_t v);

/// The current time as "2026-11-25 10:26:02 UTC", the stamp of written pages.
std::string UtcNow();

/// 42 -> "42 s", 725 -> "12 min 05 s", 7300 -> "2 h 01 min"; below 10 s one decimal;
/// `missing` for a negative or non-finite value.
std::string Duration(double seconds, const char* missing = "-");

}  // namespace rl
