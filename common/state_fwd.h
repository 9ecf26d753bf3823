// Declarations of the state-file stream and view (common/state_file.h), for headers whose classes
// save to and restore from state files without needing their definitions.
#pragma once

namespace rl {
class StateStream;
class StateView;
}  // namespace rl
