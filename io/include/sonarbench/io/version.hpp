#pragma once

namespace sonarbench::io {

/// sonarbench's version: CMake's project(VERSION), as the files it writes name their writer.
inline constexpr const char* kVersion = SONARBENCH_VERSION;

}  // namespace sonarbench::io
