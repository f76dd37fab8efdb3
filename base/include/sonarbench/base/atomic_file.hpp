#pragma once

#include <functional>
#include <ostream>
#include <string>

namespace sonarbench {

/// Writes `path` atomically: `write` fills a temporary file beside it, which is flushed, fsync'ed
/// and renamed over `path`. A failure (or an exception from `write`) removes the temporary file
/// and leaves any previous `path` untouched; throws std::runtime_error naming the file.
void WriteFileAtomically(const std::string& path, const std::function<void(std::ostream&)>& write);

}  // namespace sonarbench
