#include "sonarbench/io/output_directory.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <nlohmann/json.hpp>
#include <set>
#include <stdexcept>

#include "sonarbench/base/atomic_file.hpp"
#include "sonarbench/base/error.hpp"
#include "sonarbench/io/dataset.hpp"
#include "sonarbench/io/files.hpp"

namespace sonarbench::io {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

// A file descriptor closed when it goes out of scope.
class Fd {
 public:
  explicit Fd(int fd) : fd_(fd) {}
  ~Fd() {
    if (fd_ >= 0) ::close(fd_);
  }
  Fd(const Fd&) = delete;
  Fd& operator=(const Fd&) = delete;
  [[nodiscard]] int get() const { return fd_; }

 private:
  int fd_;
};

// A path a marker may list: relative, '/'-separated, without "." or ".." parts.
bool SafeRelative(const std::string& path) {
  if (path.empty() || path.front() == '/' || path.size() > 4096) return false;
  for (const auto& part : fs::path(path)) {
    if (part.empty() || part == "." || part == "..") return false;
  }
  return true;
}

std::optional<json> ReadJson(const fs::path& file) {
  std::error_code error;
  if (!fs::is_regular_file(file, error)) return std::nullopt;
  try {
    return json::parse(ReadFileBytes(file.string(), kMaxJsonBytes));
  } catch (const std::exception&) {
    return std::nullopt;
  }
}

// "a, b and 3 more".
std::string Listed(const std::vector<std::string>& names) {
  std::string text;
  const std::size_t shown = std::min<std::size_t>(names.size(), 5);
  for (std::size_t i = 0; i < shown; ++i) text += (i ? ", " : "") + names[i];
  if (names.size() > shown) text += " and " + std::to_string(names.size() - shown) + " more";
  return text;
}

bool Exists(const fs::path& path) {
  std::error_code error;
  return fs::exists(fs::symlink_status(path, error));
}

// The first folder on `relative`'s way down from `root` that is a symlink, or "".
std::string SymlinkedFolder(const fs::path& root, const std::string& relative) {
  fs::path folder;
  for (const auto& part : fs::path(relative).parent_path()) {
    folder /= part;
    std::error_code error;
    if (fs::is_symlink(fs::symlink_status(root / folder, error))) return folder.generic_string();
  }
  return {};
}

// Refuses `relative` when a folder on its way down from `root` (the directory named `name`) is a
// symlink: nothing is written or removed through one.
void RefuseSymlinkedFolder(const std::string& name, const fs::path& root,
                           const std::string& relative) {
  if (const std::string link = SymlinkedFolder(root, relative); !link.empty()) {
    throw InputError(name + "/" + link + " is a symlink: sonarbench writes and removes nothing " +
                     "through one (make it a folder or choose another --out)");
  }
}

// The first folder on `relative`'s way down from `root` that something else stands in, or "".
std::string BlockedFolder(const fs::path& root, const std::string& relative) {
  fs::path folder;
  for (const auto& part : fs::path(relative).parent_path()) {
    folder /= part;
    std::error_code error;
    const fs::file_status status = fs::symlink_status(root / folder, error);
    if (fs::exists(status) && !fs::is_directory(status)) return folder.generic_string();
  }
  return {};
}

std::vector<std::string> SortedUnion(std::vector<std::string> a,
                                     const std::vector<std::string>& b) {
  a.insert(a.end(), b.begin(), b.end());
  std::sort(a.begin(), a.end());
  a.erase(std::unique(a.begin(), a.end()), a.end());
  return a;
}

// Whether `output` and `input` name one file: the same path once links and ".." are resolved,
// or the same inode (a hard link).
bool SameFile(const fs::path& output, const fs::path& input) {
  std::error_code out_error;
  std::error_code in_error;
  const fs::path out = fs::weakly_canonical(output, out_error);
  const fs::path in = fs::weakly_canonical(input, in_error);
  if (!out_error && !in_error && out == in) return true;
  struct stat a {};
  struct stat b {};
  return ::stat(output.c_str(), &a) == 0 && ::stat(input.c_str(), &b) == 0 &&
         a.st_dev == b.st_dev && a.st_ino == b.st_ino;
}

bool IsFolder(const fs::path& path) {
  std::error_code error;
  return fs::is_directory(fs::symlink_status(path, error));
}

// Removes the empty folders on `relative`'s way up to `root` (never `root`).
void RemoveEmptyParents(const fs::path& root, const std::string& relative) {
  for (fs::path dir = fs::path(relative).parent_path(); !dir.empty(); dir = dir.parent_path()) {
    if (::rmdir((root / dir).c_str()) != 0) return;  // not empty, or not there
  }
}

}  // namespace

std::optional<Ownership> ReadOwnership(const fs::path& dir) {
  const auto names = [](const json& list, const char* key) {
    std::vector<std::string> files;
    for (const json& entry : list) {
      const json name = key ? (entry.is_object() ? entry.value(key, json()) : json()) : entry;
      if (name.is_string() && SafeRelative(name.get<std::string>())) files.push_back(name);
    }
    return SortedUnion(files, {});
  };
  Ownership owned;
  if (const auto marker = ReadJson(dir / OutputDirectory::kMarkerFile);
      marker && marker->is_object() && marker->value("tool", "") == "sonarbench" &&
      marker->contains("outputs") && (*marker)["outputs"].is_object()) {
    for (const auto& [command, claimed] : (*marker)["outputs"].items()) {
      if (!claimed.is_object() || !claimed.contains("files") || !claimed["files"].is_array()) {
        continue;
      }
      owned[command] = {claimed.value("config_sha256", ""), names(claimed["files"], nullptr)};
    }
    return owned;
  }
  // A report written before markers existed: report.json and the outputs it names.
  if (const auto report = ReadJson(dir / "report.json");
      report && report->is_object() && report->contains("tool") && (*report)["tool"].is_object() &&
      (*report)["tool"].value("name", "") == "sonarbench" && report->contains("outputs") &&
      (*report)["outputs"].is_object()) {
    json files = json::array({"report.json"});
    for (const auto& [what, file] : (*report)["outputs"].items()) files.push_back(file);
    owned["report"] = {"", names(files, nullptr)};
    return owned;
  }
  // A dataset written before markers existed: its manifest lists its files.
  if (const auto manifest = ReadJson(dir / "manifest.json");
      manifest && manifest->is_object() && manifest->value("format", "") == io::kDatasetFormat &&
      manifest->contains("files") && (*manifest)["files"].is_array()) {
    owned[manifest->value("source", "simulate")] = {
        manifest->value("config_sha256", ""),
        SortedUnion(names((*manifest)["files"], "path"), {"manifest.json"})};
    return owned;
  }
  return std::nullopt;
}

std::optional<std::vector<std::string>> OwnedFiles(const fs::path& dir) {
  const auto owned = ReadOwnership(dir);
  if (!owned) return std::nullopt;
  std::vector<std::string> files;
  for (const auto& [command, claimed] : *owned) files = SortedUnion(files, claimed.files);
  if (Exists(dir / OutputDirectory::kMarkerFile)) {
    files = SortedUnion(files, {OutputDirectory::kMarkerFile, OutputDirectory::kLockFile});
  }
  return files;
}

OutputDirectory::OutputDirectory(const std::string& dir, OutputClaim claim)
    : name_(dir), claim_(std::move(claim)) {
  for (const std::string& file : claim_.files) {
    if (!SafeRelative(file)) throw std::logic_error("output file '" + file + "' is not relative");
  }
  try {
    Open();
  } catch (...) {
    Release();
    throw;
  }
}

void OutputDirectory::Open() {
  if (name_.empty()) throw InputError("--out '': expected the path of an output directory");
  ResolveRoot();
  const Fd dir_fd(LockDirectory());
  if (!TakeRunLock()) return;  // joined the shards of the same run
  ClaimFiles();
  PrepareWriteRoot();
}

void OutputDirectory::ResolveRoot() {
  std::error_code error;
  const fs::path path(name_);
  if (Exists(path)) {
    root_ = fs::canonical(path, error);
    if (error) {
      throw EnvironmentError(name_ + ": cannot be used as the output directory (" +
                             error.message() + ")");
    }
    if (!fs::is_directory(root_, error)) {
      throw InputError(name_ + ": exists and is not a directory (expected an output directory)");
    }
  } else {
    CreateOutputDirectory(name_);
    created_ = true;
    root_ = fs::canonical(path);
  }
  if (root_ == root_.root_path()) {
    throw InputError(name_ +
                     ": is the file system's root; expected a directory of its own for "
                     "sonarbench's outputs (--out)");
  }
}

// The directory opened and locked, its lock serialising the set-up: the caller closes it.
int OutputDirectory::LockDirectory() const {
  const int fd = ::open(root_.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd >= 0 && ::flock(fd, LOCK_EX) == 0) return fd;
  const std::string reason = std::strerror(errno);
  if (fd >= 0) ::close(fd);
  throw EnvironmentError(name_ + ": cannot be opened (" + reason + ")");
}

bool OutputDirectory::TakeRunLock() {
  // The lock file's lock is held for the run: exclusive by a one-shot writer, shared by the
  // shards of one configuration.
  lock_created_ = !Exists(root_ / kLockFile);
  OpenLockFile();
  if (::flock(lock_fd_, LOCK_EX | LOCK_NB) != 0) {
    const auto owned = ReadOwnership(root_);
    const bool same = claim_.mode == OutputMode::kResume && !claim_.force && owned &&
                      owned->contains(claim_.command) &&
                      owned->at(claim_.command).config_sha256 == claim_.config_sha256;
    if (!same || ::flock(lock_fd_, LOCK_SH) != 0) {
      throw InputError(name_ + ": another sonarbench is writing here (" + Holder() +
                       "); wait for it to finish or choose another --out" +
                       (claim_.force ? " (--force never removes a running writer's files)" : ""));
    }
    write_root_ = root_;  // a shard of the same run: the marker lists its files already
    lock_created_ = false;
    WriteHolder(false);
    return false;
  }
  return true;
}

void OutputDirectory::ClaimFiles() {
  Ownership owned = ReadOwnership(root_).value_or(Ownership{});
  // Every writer the lock file names is gone (this one holds its lock alone): their temporary
  // files are never whole.
  dead_writers_ = LockedWriters();
  const std::vector<std::string> listed = OwnedFiles(root_).value_or(std::vector<std::string>{});
  CheckInputsAndCollisions(listed);
  ClearStage(listed);
  if (claim_.mode == OutputMode::kResume) ClaimResumable(owned);
  // A file this claim writes is this command's now, whichever wrote it before.
  for (auto& [command, claimed] : owned) {
    if (command == claim_.command) continue;
    std::erase_if(claimed.files, [&](const std::string& file) {
      return std::find(claim_.files.begin(), claim_.files.end(), file) != claim_.files.end();
    });
  }
  Claimed& mine = owned[claim_.command];
  mine = {claim_.config_sha256, SortedUnion(mine.files, claim_.files)};
  WriteMarker(owned);
  lock_created_ = false;  // listed in the marker now
  RemoveTemporaries({});
  WriteHolder(true);
}

// A resumable command continues only its own outputs of the same configuration: outputs of
// another configuration, or another command's in the way of this one's, are refused, or with
// --force removed (the other command's whole claim: a dataset is replaced whole).
void OutputDirectory::ClaimResumable(Ownership& owned) const {
  std::vector<std::string> in_the_way;
  std::vector<std::string> commands;
  for (auto& [command, claimed] : owned) {
    const bool mine = command == claim_.command;
    bool blocks = false;
    for (const std::string& file : claimed.files) {
      if (!Exists(root_ / file)) continue;
      const bool claimed_here =
          std::find(claim_.files.begin(), claim_.files.end(), file) != claim_.files.end();
      if ((mine && claimed.config_sha256 != claim_.config_sha256) || (!mine && claimed_here)) {
        in_the_way.push_back(file);
        blocks = true;
      }
    }
    if (blocks || (mine && claim_.force)) commands.push_back(command);
  }
  if (in_the_way.empty() && !claim_.force) return;
  if (!claim_.force) {
    const bool own = commands.size() == 1 && commands.front() == claim_.command;
    throw InputError(
        name_ + ": holds sonarbench " + Listed(commands) + " outputs " +
        (own ? "of another configuration (config_sha256 " + owned.at(claim_.command).config_sha256 +
                   ")"
             : "that " + claim_.command + " would write (" + Listed(in_the_way) + ")") +
        "; pass --force to replace them (only the files sonarbench listed in " + kMarkerFile +
        " are removed)");
  }
  std::vector<std::string> remove;
  for (const std::string& command : commands) {
    for (const std::string& file : owned[command].files) {
      if (Exists(root_ / file)) remove.push_back(file);
    }
    owned.erase(command);
  }
  RemoveFiles(remove);
}

void OutputDirectory::PrepareWriteRoot() {
  std::error_code error;
  write_root_ = root_;
  if (claim_.mode == OutputMode::kResume) {
    // Converted under the directory's lock, so no other writer can take it in between.
    ::flock(lock_fd_, LOCK_SH);
  } else {
    write_root_ = root_ / kStageDir;
    std::vector<std::string> staged;
    for (const std::string& file : claim_.files) staged.push_back(kStageDir + ("/" + file));
    RemoveFiles(staged);
    fs::create_directories(write_root_, error);
    if (error) throw EnvironmentError(name_ + ": cannot write in it (" + error.message() + ")");
  }
}

// What a killed one-shot writer staged: copies of files a marker lists, removed. Anything else
// in the staging folder (or a staging folder in a directory sonarbench did not write) is the
// user's, refused.
void OutputDirectory::ClearStage(const std::vector<std::string>& listed) const {
  const fs::path stage = root_ / kStageDir;
  if (!Exists(stage)) return;
  std::vector<std::string> foreign;
  if (!IsFolder(stage) || !Exists(root_ / kMarkerFile)) {
    foreign.push_back(kStageDir);
  } else {
    std::vector<std::string> staged;
    for (const std::string& file : SortedUnion(listed, claim_.files)) {
      staged.push_back(kStageDir + ("/" + file));
    }
    RemoveFiles(staged);
    std::error_code error;
    for (fs::recursive_directory_iterator it(stage, error), end; !error && it != end;
         it.increment(error)) {
      if (!it->is_directory()) foreign.push_back(fs::relative(it->path(), root_).generic_string());
    }
    if (foreign.empty()) fs::remove_all(stage, error);  // its empty folders only, by now
  }
  if (!foreign.empty()) {
    throw InputError(name_ + ": holds files sonarbench did not write: " + Listed(foreign) +
                     "; sonarbench never replaces them (move them or choose another --out)");
  }
}

void OutputDirectory::CheckInputsAndCollisions(const std::vector<std::string>& owned) const {
  std::vector<std::string> foreign;
  const std::set<std::string> mine(owned.begin(), owned.end());
  if (Exists(root_ / kMarkerFile) && !OwnedFiles(root_)) foreign.push_back(kMarkerFile);
  for (const std::string& file : claim_.files) {
    RefuseSymlinkedFolder(name_, root_, file);
    if (const std::string blocked = BlockedFolder(root_, file); !blocked.empty()) {
      foreign.push_back(blocked + " (where a folder goes)");
    } else if (!mine.contains(file) && Exists(root_ / file)) {
      foreign.push_back(file);
    }
  }
  // A folder is never sonarbench's file, whatever an edited marker lists.
  std::vector<std::string> folders;
  for (const std::string& file : SortedUnion(owned, claim_.files)) {
    if (IsFolder(root_ / file)) folders.push_back(file);
  }
  if (!folders.empty()) {
    throw InputError(name_ + ": " + Listed(folders) + ", where sonarbench writes a file, is a " +
                     "folder (the marker " + kMarkerFile + " may have been edited); sonarbench " +
                     "never removes a folder (move it or choose another --out)");
  }
  std::sort(foreign.begin(), foreign.end());
  foreign.erase(std::unique(foreign.begin(), foreign.end()), foreign.end());
  if (!foreign.empty()) {
    throw InputError(name_ + ": holds files sonarbench did not write: " + Listed(foreign) +
                     "; sonarbench never replaces them (move them or choose another --out)");
  }
  for (const std::string& input : claim_.inputs) {
    for (const auto* list : {&claim_.files, &owned}) {
      for (const std::string& file : *list) {
        if (SameFile(root_ / file, input)) {
          throw InputError(name_ + "/" + file + " is the input " + input +
                           ": sonarbench never overwrites or removes its inputs (choose another "
                           "--out)");
        }
      }
    }
  }
}

void OutputDirectory::RemoveFiles(const std::vector<std::string>& files) const {
  for (const std::string& file : files) {
    RefuseSymlinkedFolder(name_, root_, file);
    std::error_code error;
    fs::remove(root_ / file, error);
    if (error) {
      throw EnvironmentError(name_ + "/" + file + ": cannot be removed (" + error.message() + ")");
    }
  }
  RemoveTemporaries(files);
  for (const std::string& file : files) RemoveEmptyParents(root_, file);
}

void OutputDirectory::RemoveTemporaries(const std::vector<std::string>& files) const {
  // "NAME.tmp.PID" beside a listed or given NAME, of a writer the lock file names (one that
  // died): WriteFileAtomically's. A file so named by anyone else stays.
  if (dead_writers_.empty()) return;
  const auto listed = OwnedFiles(root_).value_or(std::vector<std::string>{});
  const std::vector<std::string> all = SortedUnion(files, listed);
  const std::set<std::string> names(all.begin(), all.end());
  std::set<fs::path> folders;
  for (const std::string& file : all) folders.insert(fs::path(file).parent_path());
  for (const fs::path& folder : folders) {
    std::error_code error;
    for (fs::directory_iterator it(root_ / folder, error), end; !error && it != end;
         it.increment(error)) {
      const std::string name = it->path().filename().string();
      const auto at = name.rfind(".tmp.");
      if (at == std::string::npos || !names.contains((folder / name.substr(0, at)).string()) ||
          !dead_writers_.contains(name.substr(at + 5))) {
        continue;
      }
      std::error_code ignored;
      fs::remove(it->path(), ignored);
    }
  }
}

void OutputDirectory::WriteMarker(const Ownership& owned) const {
  json outputs = json::object();
  for (const auto& [command, claimed] : owned) {
    if (claimed.files.empty()) continue;
    outputs[command] = {{"config_sha256", claimed.config_sha256}, {"files", claimed.files}};
  }
  const json marker = {{"tool", "sonarbench"},
                       {"about",
                        "sonarbench wrote the files listed here, command by command, and may "
                        "replace or remove them; it touches nothing else in this directory"},
                       {"outputs", outputs}};
  WriteFileAtomically((root_ / kMarkerFile).string(),
                      [&](std::ostream& out) { out << marker.dump(2) << "\n"; });
}

bool OutputDirectory::HoldsRecord() const {
  const auto owned = ReadOwnership(root_);
  return owned && owned->contains(claim_.command) && Exists(root_ / claim_.record) &&
         !IsFolder(root_ / claim_.record);
}

void OutputDirectory::DiscardStaged() const {
  if (claim_.mode != OutputMode::kReplace || write_root_ == root_) return;
  for (const std::string& file : claim_.files) {
    std::error_code ignored;
    fs::remove(write_root_ / file, ignored);
    RemoveEmptyParents(write_root_, file);  // never write_root_ itself
  }
}

void OutputDirectory::Commit() {
  if (claim_.mode != OutputMode::kReplace) return;
  std::vector<std::string> staged;
  for (const auto& entry : fs::recursive_directory_iterator(write_root_)) {
    if (entry.is_directory()) continue;
    staged.push_back(fs::relative(entry.path(), write_root_).generic_string());
  }
  for (const std::string& file : staged) {
    if (std::find(claim_.files.begin(), claim_.files.end(), file) == claim_.files.end()) {
      throw std::logic_error(name_ + ": staged " + file + ", which " + claim_.command +
                             " does not claim");
    }
  }
  // The record goes first, so no reader trusts a mix of two runs' files.
  std::vector<std::string> stale;
  for (const std::string& file : claim_.files) {
    if (file == claim_.record || std::find(staged.begin(), staged.end(), file) == staged.end()) {
      stale.push_back(file);
    }
  }
  std::stable_partition(stale.begin(), stale.end(),
                        [&](const std::string& file) { return file == claim_.record; });
  for (const std::string& file : stale) {
    std::error_code error;
    fs::remove(root_ / file, error);
    if (error) {
      throw EnvironmentError(name_ + "/" + file + ": cannot be removed (" + error.message() + ")");
    }
    RemoveEmptyParents(root_, file);
  }
  std::stable_partition(staged.begin(), staged.end(),
                        [&](const std::string& file) { return file != claim_.record; });
  for (const std::string& file : staged) {
    std::error_code error;
    fs::create_directories((root_ / file).parent_path(), error);
    if (!error) fs::rename(write_root_ / file, root_ / file, error);
    if (error) {
      throw EnvironmentError(name_ + "/" + file + ": cannot be written (" + error.message() + ")");
    }
    RemoveEmptyParents(write_root_, file);
  }
  const Fd dir_fd(::open(root_.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC));
  if (dir_fd.get() >= 0) ::fsync(dir_fd.get());
  ::rmdir(write_root_.c_str());
  committed_ = true;
}

OutputDirectory::~OutputDirectory() { Release(); }

void OutputDirectory::Release() noexcept {
  if (lock_fd_ < 0) {
    if (created_) ::rmdir(root_.c_str());
    return;
  }
  try {
    // A lock file made by an open that was refused goes again (no marker lists it).
    if (lock_created_) ::unlink((root_ / kLockFile).c_str());
    if (!committed_ && write_root_ != root_) {
      DiscardStaged();
      ::rmdir(write_root_.c_str());
    }
    // The last writer out removes the temporaries of the shards that died before it, and leaves
    // the lock file empty: the same inputs, the same bytes.
    const bool last = ::flock(lock_fd_, LOCK_EX | LOCK_NB) == 0;
    if (last && !lock_created_) {
      dead_writers_ = LockedWriters();
      RemoveTemporaries({});
      if (::ftruncate(lock_fd_, 0) != 0) {
        // Only the writers' names are left in it.
      }
    }
    // A directory made for nothing goes again, unless another writer has joined.
    if (created_ && !committed_ && last) {
      std::error_code error;
      std::size_t others = 0;
      for (fs::directory_iterator it(root_, error), end; !error && it != end; it.increment(error)) {
        const std::string name = it->path().filename().string();
        others += name != kMarkerFile && name != kLockFile;
      }
      if (!error && others == 0) {
        fs::remove(root_ / kMarkerFile, error);
        fs::remove(root_ / kLockFile, error);
        ::rmdir(root_.c_str());
      }
    }
  } catch (...) {
    // A destructor must not throw; what is left is listed in the marker.
  }
  ::close(lock_fd_);
  lock_fd_ = -1;
}

}  // namespace sonarbench::io
