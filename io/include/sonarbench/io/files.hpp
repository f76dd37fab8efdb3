#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>

// The bench's inputs and output directories: files read within a budget checked before the
// allocation, output directories checked before any work.
namespace sonarbench {

/// Refuses `dir` as a command's output directory, before any work, when something other than a
/// directory is in its way, or when it does not exist and its nearest existing ancestor is not a
/// directory this process may write in: throws InputError naming it. Makes nothing.
void CheckOutputDirectory(const std::string& dir);

/// Creates the output directory `dir` and its parents; throws InputError naming it and why when
/// it cannot be (a file in the way, no permission).
void CreateOutputDirectory(const std::string& dir);

/// Refuses `path` as an exported file unless it is absent, or, with `force`, a file of `kind`
/// ("an MCAP file") that sonarbench wrote (`ours`): throws InputError naming it. Readies its
/// folder.
void ClaimExportFile(const std::string& path, bool force, bool ours, const std::string& kind);

/// Removes what a killed writer of `path` left: "PATH.tmp.PID" files (WriteFileAtomically's) of a
/// process no longer running whose first bytes `ours` recognises as sonarbench's. Anything else so
/// named stays.
void RemoveDeadTemporaries(const std::string& path,
                           const std::function<bool(const std::string& head)>& ours);

/// The most the readers take from one file, checked before they allocate (bytes).
/// A YAML file: a scene, a sensor model, a mapping configuration (yaml-cpp takes ~100x its size).
inline constexpr std::uint64_t kMaxYamlBytes = std::uint64_t{2} << 20;
/// A JSON record: a dataset's manifest, an output directory's marker (nlohmann takes ~10-20x).
inline constexpr std::uint64_t kMaxJsonBytes = std::uint64_t{16} << 20;
/// A log (.mat or MCAP) by default: the file and what it decompresses to, together.
inline constexpr std::uint64_t kMaxLogBytes = std::uint64_t{384} << 20;

/// Range bins of one beam: a Micron's 399, an imaging sonar's some thousands; what the readers,
/// the sensor model and the mapper take.
inline constexpr std::size_t kMaxBinsPerBeam = 16384;

/// Throws InputError naming `path` unless it is a regular file of at most `max_bytes` bytes: a
/// FIFO, device, socket or directory is refused by its type, never read. Returns its size.
std::uint64_t CheckInputFile(const std::string& path, std::uint64_t max_bytes);

/// The whole content of `path`, checked as CheckInputFile does (on the opened descriptor, which
/// never blocks on a FIFO); throws InputError naming it when it cannot be read.
[[nodiscard]] std::string ReadFileBytes(const std::string& path, std::uint64_t max_bytes);

/// `bytes` for a message: "1.5 MiB", "2047 bytes" (exact below 10 KiB).
[[nodiscard]] std::string ByteCount(std::uint64_t bytes);

}  // namespace sonarbench
