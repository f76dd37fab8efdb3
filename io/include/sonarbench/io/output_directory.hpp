#pragma once

#include <filesystem>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <vector>

namespace sonarbench::io {

/// How a command's outputs meet the outputs already in its directory.
enum class OutputMode {
  /// One shot (run, map, fidelity): outputs go to a staging folder inside the directory and
  /// Commit moves them into place, the record last; the outputs there before go whole.
  kReplace,
  /// Resumable (simulate, import, sweep): outputs are written in place, each file atomically; a
  /// run of the same configuration resumes (shards of it write at once), another configuration
  /// is refused unless `force`.
  kResume,
};

/// What a command will write into its output directory.
struct OutputClaim {
  /// The command's name, for messages and the marker.
  std::string command;
  /// What determines the outputs: writers of another configuration are refused.
  std::string config_sha256;
  OutputMode mode = OutputMode::kReplace;
  /// Every file the command may write, relative to the directory, '/'-separated.
  std::vector<std::string> files;
  /// The file a reader trusts the others by (report.json, manifest.json): one of `files`.
  std::string record;
  /// Files the command reads: never written or removed.
  std::vector<std::string> inputs;
  /// kResume: remove what the marker lists for this command before writing.
  bool force = false;
};

/// What one command claimed in an output directory: its configuration and its files.
struct Claimed {
  std::string config_sha256;
  std::vector<std::string> files;
};
/// Each command's claim, by the command's name.
using Ownership = std::map<std::string, Claimed>;

/// A command's output directory, owned through a marker (`kMarkerFile`) that lists, command by
/// command, every file sonarbench may write there, and guarded by a lock (`kLockFile`): one
/// configuration writes at a time. Only files the marker lists are ever replaced or removed (by
/// --force, only the same command's); a directory tree never is, nor anything behind a symlink
/// inside the directory.
/// Errors (another writer, files of the user's in the way, a read-only or full disk) throw
/// InputError naming the directory, the files or the OS's reason.
class OutputDirectory {
 public:
  static constexpr const char* kMarkerFile = ".sonarbench-outputs.json";
  static constexpr const char* kLockFile = ".sonarbench.lock";
  static constexpr const char* kStageDir = ".sonarbench-stage";

  /// Makes `dir` (following a symlink to one), takes the lock and writes the marker.
  OutputDirectory(const std::string& dir, OutputClaim claim);
  /// Releases the lock. Uncommitted staged files are removed, and so is a directory this object
  /// made when it holds nothing but the marker and the lock.
  ~OutputDirectory();
  OutputDirectory(const OutputDirectory&) = delete;
  OutputDirectory& operator=(const OutputDirectory&) = delete;

  /// The directory as the user named it, for messages.
  [[nodiscard]] const std::string& name() const { return name_; }
  /// Where outputs are written: the staging folder (kReplace) or the directory (kResume).
  [[nodiscard]] const std::filesystem::path& write_root() const { return write_root_; }
  /// The directory itself (a symlink's target).
  [[nodiscard]] const std::filesystem::path& root() const { return root_; }

  /// kReplace: removes the record there, then the claimed files this run did not
  /// stage, moves the staged files into place and the record last. Throws logic_error for a
  /// staged file outside the claim.
  void Commit();

  /// kReplace: removes what this run staged, so a Commit moves only what is staged after.
  void DiscardStaged() const;
  /// Whether the directory holds this command's record (a complete earlier result).
  [[nodiscard]] bool HoldsRecord() const;

 private:
  void Open();
  // Open's steps: the root made or found; the directory's lock for the set-up; the run's lock
  // (false: joined the shards of the same run, nothing more to do); this claim's files listed in
  // the marker; the staging folder.
  void ResolveRoot();
  [[nodiscard]] int LockDirectory() const;
  [[nodiscard]] bool TakeRunLock();
  void OpenLockFile();
  void ClaimFiles();
  void ClaimResumable(Ownership& owned) const;
  void ClearStage(const std::vector<std::string>& listed) const;
  void PrepareWriteRoot();
  void Release() noexcept;
  void CheckInputsAndCollisions(const std::vector<std::string>& owned) const;
  void RemoveFiles(const std::vector<std::string>& files) const;
  void RemoveTemporaries(const std::vector<std::string>& files) const;
  void WriteMarker(const Ownership& owned) const;
  void WriteHolder(bool first) const;
  [[nodiscard]] std::string LockText() const;
  // The pids the lock file's lines name ("sonarbench CMD, pid N on HOST, ..."): its writers
  // since the last one out emptied it.
  [[nodiscard]] std::set<std::string> LockedWriters() const;
  [[nodiscard]] std::string Holder() const;

  std::string name_;
  OutputClaim claim_;
  std::filesystem::path root_;
  std::filesystem::path write_root_;
  int lock_fd_ = -1;
  bool created_ = false;
  bool lock_created_ = false;
  bool committed_ = false;
  // The pids of the writers before this one that the lock file names (all gone): whose
  // temporary files may be removed.
  std::set<std::string> dead_writers_;
};

/// The claims an output directory's marker records (or, for a dataset written before markers,
/// its manifest), or nullopt when it has neither: a directory sonarbench did not write. Paths
/// that are not plainly relative are dropped.
[[nodiscard]] std::optional<Ownership> ReadOwnership(const std::filesystem::path& dir);

/// Every file of ReadOwnership's claims, with the marker and the lock; nullopt as there.
[[nodiscard]] std::optional<std::vector<std::string>> OwnedFiles(const std::filesystem::path& dir);

}  // namespace sonarbench::io
