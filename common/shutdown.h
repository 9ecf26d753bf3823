// Clean shutdown on SIGINT and SIGTERM: the handler only sets a flag that main loops poll.
#pragma once

namespace rl {

// Installs handlers for SIGINT and SIGTERM (and ignores SIGPIPE). Call once, early in main().
void InstallStopHandlers();

// True once SIGINT or SIGTERM arrived (or RequestStop() was called).
bool StopRequested();

void RequestStop();

}  // namespace rl
