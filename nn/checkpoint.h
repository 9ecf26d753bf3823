// Binary checkpoint files: a network's architecture and parameters plus training metadata.
//
// Layout (all integers and floats little-endian):
//   char[8]  magic "RLCKPT01"
//   u32      format version (1)
//   u64      total file size in bytes, CRC included
//   u32 n, char[n]   architecture string (Sequential::Architecture())
//   i64      update        i64 env_steps     f64 wall_seconds     u64 run_id
//   u32 n, char[n]   note (free-form, e.g. the run's configuration)
//   u64 n, f32[n]    parameters then buffers, in Sequential::GetFlat() order
//   u32      CRC-32 (IEEE) of every byte before it
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace rl::nn {

/// Training progress stored with the parameters.
struct CheckpointMeta {
  int64_t update = 0;       ///< Learner updates (gradient steps) done.
  int64_t env_steps = 0;    ///< Environment steps consumed.
  double wall_seconds = 0;  ///< Training wall-clock time, seconds.
  uint64_t run_id = 0;      ///< Identifies the training run.
  std::string note;         ///< Free-form text, e.g. the configuration of the run.
};

/// A network in a form that can be rebuilt: BuildFromArchitecture(architecture) then
/// SetFlat(params). `params` is Sequential::GetFlat(): the parameters, then the buffers (running
/// statistics), FlatSize() floats.
struct Checkpoint {
  std::string architecture;
  CheckpointMeta meta;
  std::vector<float> params;
};

/// Writes `ckpt` to `path` atomically: into "<path>.tmp.<pid>", flushed and fsync'ed, then renamed
/// over `path`, then the directory is fsync'ed. Readers see either the old file or the complete
/// new one. Throws std::runtime_error naming the path and the errno text on failure, after
/// removing the temporary file.
void SaveCheckpoint(const std::string& path, const Checkpoint& ckpt);

/// Reads and verifies a checkpoint. Throws std::runtime_error naming the path and the reason:
/// cannot open, not a checkpoint file (wrong magic), unsupported version, truncated, corrupted
/// (checksum mismatch or inconsistent lengths), or a parameter count that does not match the
/// architecture's FlatSize().
Checkpoint LoadCheckpoint(const std::string& path);

/// LoadCheckpoint() of a file already read into memory (`bytes`, the whole file); errors name
/// `name` where LoadCheckpoint's name the path.
Checkpoint ParseCheckpoint(std::string_view bytes, const std::string& name);

/// The name the learner gives the checkpoint of update `update`: "ckpt-<update, 9 digits or
/// more>.bin".
std::string CheckpointFileName(int64_t update);

/// The checkpoint files the learner wrote in `dir` (regular files named as CheckpointFileName
/// names them), their paths by update, oldest first; none when `dir` cannot be read.
std::vector<std::string> CheckpointFilesIn(const std::string& dir);

/// The learner's state (its networks, optimizers and counters: common/state_file.h), kept in the
/// run's checkpoint folder beside the checkpoints, under this name: not a checkpoint file.
inline constexpr std::string_view kLearnerStateFile = "learner-state.bin";

}  // namespace rl::nn
