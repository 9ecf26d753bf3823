// Writing a file so that a reader (or a crash) sees the old file or the whole new one, never a
// part of it: the one way every process of a run writes checkpoints, reports, pictures and
// snapshots.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace rl {

/// Writes `bytes` to a temporary file beside `path` (path + ".tmp.<pid>"), fsyncs it and renames
/// it over `path` (RenameIntoPlace). Throws std::runtime_error "cannot write <what> <path>:
/// <step>: <strerror>" on failure, after removing the temporary file.
void WriteFileAtomically(const std::string& path, std::string_view bytes,
                         const std::string& what = "file");

/// Renames the complete file `tmp` over `path`, then fsyncs the directory so that the rename
/// survives a crash (file systems that cannot fsync a directory are tolerated). For writers that
/// produce the temporary file themselves (a video encoder). Throws std::runtime_error as above and
/// removes `tmp` on failure.
void RenameIntoPlace(const std::string& tmp, const std::string& path,
                     const std::string& what = "file");

/// The temporary name WriteFileAtomically uses for `path` (with the caller's pid).
std::string TemporaryPathFor(const std::string& path);

/// Removes the temporary files that writers killed mid-write left in `dir`: every regular file
/// named <name>.tmp.<digits> whose <name> starts with `prefix` (any name for an empty prefix),
/// except this process's own. For a process that is the only writer of those names, as it starts
/// and before it writes there. Errors are ignored (a file that stays is only litter). Returns the
/// number of files removed. Cost: one pass over the folder.
int RemoveStaleTemporaries(const std::string& dir, std::string_view prefix = {});

/// The same atomic write, streamed: for files too large to build in memory, and for writers that
/// must not allocate, lock or throw (the child of fork() in a process with other threads, which
/// writes a copy-on-write snapshot). The constructor prepares every name (it allocates); Open(),
/// Write(), Commit() and the destructor make system calls only: no allocation, no lock, no
/// exception. A failure returns false and leaves its step and errno in the stream; the temporary
/// file is then removed. Not thread-safe.
class AtomicFileStream {
 public:
  explicit AtomicFileStream(std::string path);
  AtomicFileStream(const AtomicFileStream&) = delete;
  AtomicFileStream& operator=(const AtomicFileStream&) = delete;
  /// Closes and removes a temporary file that was not committed.
  ~AtomicFileStream();

  /// Creates the temporary file path + ".tmp.<pid>", with the pid of the process calling Open
  /// (a fork()ed child gets a name of its own). One Open per stream.
  bool Open();
  /// Appends `size` bytes (retrying short writes and EINTR).
  bool Write(const void* data, size_t size);
  /// Fsyncs and closes the temporary file, renames it over the path and fsyncs the directory.
  bool Commit();

  const std::string& path() const { return path_; }
  /// The temporary file's name (valid after Open()).
  const char* temporary_path() const { return tmp_.data(); }
  int64_t bytes_written() const { return bytes_; }
  /// The failed step ("create", "write", "sync", "close", "rename", "open directory", "sync
  /// directory"), or nullptr; and its errno.
  const char* failed_step() const { return step_; }
  int error() const { return error_; }
  /// "cannot write <what> <path>: <step> <file>: <strerror>" for the failure (allocates).
  std::string ErrorMessage(const std::string& what) const;

 private:
  // Records a failure, closes and removes the temporary file; returns false.
  bool Fail(const char* step, int err, bool remove);

  std::string path_;
  std::vector<char> tmp_;  // NUL-terminated temporary name, room for any pid
  std::string dir_;
  size_t tmp_stem_ = 0;  // length of path + ".tmp."
  int fd_ = -1;
  bool open_ = false;  // a temporary file exists and is not committed
  int64_t bytes_ = 0;
  const char* step_ = nullptr;
  int error_ = 0;
};

}  // namespace rl
