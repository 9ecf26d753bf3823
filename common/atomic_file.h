// Writing a file so that a reader (or a crash) sees the old file or the whole new one, never a
// part of it: the one way every process of a run writes checkpoints, reports and pictures.
#pragma once

#include <string>
#include <string_view>

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

/// The temporary name WriteFileAtomically uses for `path`.
std::string TemporaryPathFor(const std::string& path);

}  // namespace rl
