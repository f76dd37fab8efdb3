#pragma once

// What every harness shares: a scratch folder of its own, and the contract every reader keeps.
// Bad input ends in InputError with a message; any other exception escapes to libFuzzer, which
// reports it as a crash, as it does an abort, a sanitizer report, a leak, a slow input
// (-timeout) or an allocation past -malloc_limit_mb.

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>

#include "sonarbench/base/error.hpp"

namespace sonarbench::fuzz {

/// A folder under $TMPDIR made once per process and removed when it exits.
inline const std::filesystem::path& ScratchDir() {
  static const std::filesystem::path dir = [] {
    std::string pattern = (std::filesystem::temp_directory_path() / "sonarbench-fuzz-XXXXXX");
    if (mkdtemp(pattern.data()) == nullptr) std::abort();
    std::atexit([] { std::filesystem::remove_all(ScratchDir()); });
    return std::filesystem::path(pattern);
  }();
  return dir;
}

/// Writes `bytes` to `path` whole, creating its folder.
inline void WriteBytes(const std::filesystem::path& path, std::string_view bytes) {
  std::filesystem::create_directories(path.parent_path());
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  if (!out) std::abort();
}

/// Runs `read` on one input: an InputError must carry a message; anything else escapes.
template <typename Read>
int KeepsTheContract(Read&& read) {
  try {
    read();
  } catch (const InputError& e) {
    if (std::string_view(e.what()).empty()) __builtin_trap();
  }
  return 0;
}

inline std::string_view AsText(const std::uint8_t* data, std::size_t size) {
  return {reinterpret_cast<const char*>(data), size};
}

}  // namespace sonarbench::fuzz
