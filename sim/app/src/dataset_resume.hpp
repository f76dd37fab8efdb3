#pragma once

#include <cstddef>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

namespace sonarbench::sim {

/// Where a resumable dataset writer vouches for what it wrote: a record a sweep, listing each of
/// the sweep's files with its sha256 and the configuration it was written for.
inline constexpr const char* kSweepRecordFolder = ".sonarbench-partial";

/// ".sonarbench-partial/sweep_0012.json".
[[nodiscard]] std::string SweepRecordFile(std::size_t sweep);

/// The files sweep `sweep` of a dataset holds (its truth with `simulated`, its labels with
/// `labels`), relative to the dataset's folder.
[[nodiscard]] std::vector<std::string> SweepFiles(std::size_t sweep, bool simulated, bool labels);

/// What a resume may keep of a dataset directory written for `config`: a file is kept only when
/// a record of this configuration (the sweep's, or a finished manifest's) lists it with the
/// sha256 it still has. Everything else is written again.
class ResumeRecords {
 public:
  ResumeRecords(std::filesystem::path root, std::string config);

  /// Whether the manifest is of this configuration and every file it lists has its hash: the
  /// dataset is complete. A manifest of this configuration that fails is removed (it is the
  /// writer's own), and the hashes it lists still vouch for the files that match them.
  [[nodiscard]] bool ManifestComplete();
  /// Whether every file of `files` is a regular file with the hash a record gives it.
  [[nodiscard]] bool Vouched(std::size_t sweep, const std::vector<std::string>& files) const;
  /// Hashes `files` as they are on disk and writes sweep `sweep`'s record (atomically).
  void Record(std::size_t sweep, const std::vector<std::string>& files) const;
  /// Removes the sweeps' records (once the manifest vouches for everything).
  void RemoveAll(std::size_t sweeps) const;

 private:
  [[nodiscard]] std::map<std::string, std::string> SweepHashes(std::size_t sweep) const;

  std::filesystem::path root_;
  std::string config_;
  // path -> sha256, from a manifest of this configuration.
  std::map<std::string, std::string> manifest_;
};

}  // namespace sonarbench::sim
