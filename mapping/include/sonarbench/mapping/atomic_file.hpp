#pragma once

#include <functional>
#include <ostream>
#include <string>

namespace sonarbench {

/// Writes `path` atomically: `write` fills a temporary file beside it, which is flushed, fsync'ed
/// and renamed over `path`. A failure (or an exception from `write`) removes the temporary file
/// and leaves any previous `path` untouched; throws std::runtime_error naming the file.
void WriteFileAtomically(const std::string& path, const std::function<void(std::ostream&)>& write);

/// Refuses `dir` as a command's output directory, before any work, when something other than a
/// directory is in its way, or when it does not exist and its nearest existing ancestor is not a
/// directory this process may write in: throws InputError naming it. Makes nothing.
void CheckOutputDirectory(const std::string& dir);

/// Creates the output directory `dir` and its parents; throws InputError naming it and why when
/// it cannot be (a file in the way, no permission).
void CreateOutputDirectory(const std::string& dir);

/// The whole content of `path`; throws InputError naming it when it cannot be read.
[[nodiscard]] std::string ReadFileBytes(const std::string& path);

}  // namespace sonarbench
