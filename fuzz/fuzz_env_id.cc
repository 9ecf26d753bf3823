// Fuzz target: the env-id parser (envs/pixel_spec.h ParseEnvId) and the static spec lookup that
// every process does with the preset's env id (envs/specs.h LookupSpec: registered ids, pixel
// pipeline settings, the resulting frame geometry). Builds no env. Input: the id's text.
// Contract checked: a bad id is refused with std::invalid_argument.
#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>

#include "envs/pixel_spec.h"
#include "envs/specs.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string id(reinterpret_cast<const char*>(data), size);
  try {
    rl::envs::ParseEnvId(id);
  } catch (const std::invalid_argument&) {
  }
  try {
    rl::envs::LookupSpec(id);
  } catch (const std::invalid_argument&) {
  }
  return 0;
}
