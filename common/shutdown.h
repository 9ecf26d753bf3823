// Clean shutdown on SIGINT, SIGTERM and SIGUSR2: the handler only sets a flag that main loops poll.
// SIGUSR2 is the stop of a process run as a Slurm step: srun passes USR1 and USR2 on to its task,
// while TERM to srun makes it SIGKILL the task.
#pragma once

namespace rl {

// Installs handlers for SIGINT, SIGTERM and SIGUSR2 (and ignores SIGPIPE). Call once, early in
// main().
void InstallStopHandlers();

// True once SIGINT, SIGTERM or SIGUSR2 arrived (or RequestStop() was called).
bool StopRequested();

void RequestStop();

}  // namespace rl
