// Test messages written from the .lcm schemas (common/lcm_schema.h), for any type of lcmtypes/.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace rl {

/// The encoded bytes of a message of struct `type` (its 8-byte fingerprint first): every
/// variable dimension is `n`, and every other value comes from `salt` (small integers, booleans
/// 0 or 1, finite floats, short strings), so that two salts differ in every field. Throws
/// std::out_of_range for a type without a schema.
std::vector<uint8_t> SchemaMessage(const std::string& type, int64_t fingerprint, int64_t n,
                                   int salt);

}  // namespace rl
