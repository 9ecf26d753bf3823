// The checkpoint files the evaluator reads because a message on RL_CHECKPOINT names them.
//
// Whoever holds the run's key can announce any path: /dev/zero (a read that never ends), a FIFO
// (an open that never returns), a symbolic link to a file elsewhere, or a name with "..". So an
// announced path is read only when it names a regular file, not a symbolic link, directly inside
// the run's checkpoint folder, of at most a size bound; it is opened without blocking and read
// up to the bound, and everything else is refused with the reason. The learner's own
// announcements (<out>/checkpoints/ckpt-<update>.bin) always qualify. Not for paths a user gives
// by hand (the evaluator's --checkpoint FILE reads any file: nn::LoadCheckpoint).
#pragma once

#include <cstdint>
#include <string>

#include "nn/checkpoint.h"
#include "nn/sequential.h"

namespace rl::evaluator {

/// The default bound on an announced checkpoint's size: a network of the most parameters nn
/// builds (nn::kMaxArchitectureParameters floats) with 16 MiB of architecture, note and
/// header. Every checkpoint a learner writes is smaller; a larger file could not load anyway.
inline constexpr int64_t kMaxAnnouncedCheckpointBytes =
    nn::kMaxArchitectureParameters * 4 + (int64_t{16} << 20);

/// Reads the checkpoint file `announced` names, which must be a regular file (not a symbolic
/// link) directly inside `folder` (both resolved: a parent path with symbolic links or ".." is
/// compared by where it leads) of at most max_bytes, and parses it (nn::ParseCheckpoint).
/// Throws std::runtime_error saying why the path or the file is refused; the path is quoted
/// with its control characters replaced and cut at 200 characters. O(file size); never blocks
/// on the file (opened O_NONBLOCK).
nn::Checkpoint ReadAnnouncedCheckpoint(const std::string& announced, const std::string& folder,
                                       int64_t max_bytes = kMaxAnnouncedCheckpointBytes);

}  // namespace rl::evaluator
