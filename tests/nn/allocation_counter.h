// Counts heap allocations made by the test process, to check that hot paths do not allocate.
#pragma once

#include <cstdint>

namespace rl::nn::testing {

/// False when the count is unavailable (under AddressSanitizer, which owns malloc).
bool AllocationCountingAvailable();

/// Number of malloc/calloc/realloc/aligned allocations so far (operator new and Eigen both end
/// up in malloc).
int64_t AllocationCount();

}  // namespace rl::nn::testing
