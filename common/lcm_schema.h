// The message schemas of lcmtypes/*.lcm, read at run time from the .lcm text itself, so that
// checks of the encoded bytes can never fall out of step with the types.
//
// The build embeds every .lcm file of lcmtypes/ (lcmtypes/CMakeLists.txt writes them into
// lcm_schemas.inc); LcmSchemas() parses them once. PrescanEncoded() walks an encoded message
// field by field, as lcm-gen's decoder would, and checks every string and array length against
// the buffer before the decoder sizes a vector from it (a forged length would otherwise make a
// daemon allocate gigabytes).
#pragma once

#include <cstddef>
#include <cstdint>
#include <map>
#include <string>
#include <string_view>
#include <vector>

namespace rl {

// Largest array a message may carry (elements), far above any real message.
inline constexpr int64_t kMaxArrayElements = 64 * 1024 * 1024;

// One field of a struct: `type name[dim_1][dim_2]...;`.
struct LcmField {
  std::string type;  // a primitive (int8_t ... double, byte, boolean, string) or a struct name
  std::string name;
  // Array dimensions, outermost first: a number (fixed size) or the name of an earlier integer
  // field of the same struct (variable size). Empty for a scalar.
  std::vector<std::string> dims;
};

struct LcmStruct {
  std::string package;
  std::string name;
  std::vector<LcmField> fields;
};

/// Parses the text of one .lcm file: an optional `package name;` and one `struct name { ... }`.
/// Comments (// and /* */) are skipped. Constants, multiple structs and anything else outside
/// this grammar throw std::invalid_argument naming the file and what was expected; so does a
/// variable dimension that is not an earlier integer field.
LcmStruct ParseLcmStruct(std::string_view text, const std::string& file_name);

/// Every embedded schema, by struct name (parsed on the first call; thread-safe).
const std::map<std::string, LcmStruct>& LcmSchemas();

/// Walks the encoded bytes of a message of struct `type` (the 8-byte fingerprint, then its
/// fields; nested structs without their own fingerprint, as LCM encodes them). Returns nullptr
/// when every length fits and the message ends exactly at the end of the buffer, else a short
/// reason: "truncated or bad length" (a length past the end, negative, or above
/// kMaxArrayElements elements), "string with a NUL inside" (or without its terminating NUL: it
/// would not re-encode as received), "trailing bytes", or "no schema" for an unknown type.
/// O(size + fields); allocates nothing after the first call.
const char* PrescanEncoded(std::string_view type, const uint8_t* data, size_t size);

}  // namespace rl
