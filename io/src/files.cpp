#include "sonarbench/io/files.hpp"

#include <fcntl.h>
#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>

#include "sonarbench/base/error.hpp"
#include "sonarbench/io/text.hpp"

namespace sonarbench {

void CheckOutputDirectory(const std::string& dir) {
  namespace fs = std::filesystem;
  std::error_code error;
  if (fs::exists(dir, error)) {
    if (!fs::is_directory(dir, error)) {
      throw InputError(dir + ": exists and is not a directory (expected an output directory)");
    }
    return;
  }
  // The directory would be made in its nearest existing ancestor: that must be a directory
  // this process may write in.
  fs::path ancestor = fs::absolute(dir, error).parent_path();
  while (!ancestor.empty() && !fs::exists(ancestor, error) && ancestor != ancestor.root_path()) {
    ancestor = ancestor.parent_path();
  }
  std::string why;
  if (!fs::is_directory(ancestor, error)) {
    why = " is not a directory";
  } else if (::access(ancestor.c_str(), W_OK | X_OK) != 0) {
    why = std::string(": ") + std::strerror(errno);  // "Permission denied", "Read-only file system"
  }
  if (!why.empty()) {
    throw EnvironmentError(dir + ": cannot be made the output directory (" + ancestor.string() +
                           why + "; expected a path where a directory can be made)");
  }
}

void CreateOutputDirectory(const std::string& dir) {
  CheckOutputDirectory(dir);
  std::error_code error;
  std::filesystem::create_directories(dir, error);
  if (error) {
    throw EnvironmentError(dir + ": cannot be made the output directory (" + error.message() +
                           "; expected a path where a directory can be made)");
  }
}

void ClaimExportFile(const std::string& path, bool force, bool ours, const std::string& kind) {
  std::error_code error;
  if (std::filesystem::exists(path, error) || std::filesystem::is_symlink(path, error)) {
    if (!std::filesystem::is_regular_file(path, error)) {
      throw InputError(path + ": exists and is not a file; choose another --out");
    }
    if (!ours) {
      throw InputError(path + ": exists and is not " + kind +
                       " sonarbench wrote; sonarbench never replaces it (--force neither): "
                       "choose another --out");
    }
    if (!force) {
      throw InputError(path + ": exists (" + kind +
                       " sonarbench wrote); pass --force to replace it");
    }
  }
  const std::filesystem::path parent = std::filesystem::path(path).parent_path();
  if (!parent.empty()) CheckOutputDirectory(parent.string());
  if (!parent.empty()) CreateOutputDirectory(parent.string());
}

void RemoveDeadTemporaries(const std::string& path,
                           const std::function<bool(const std::string& head)>& ours) {
  namespace fs = std::filesystem;
  const fs::path target(path);
  const fs::path folder = target.parent_path().empty() ? fs::path(".") : target.parent_path();
  const std::string prefix = target.filename().string() + ".tmp.";
  std::error_code error;
  for (fs::directory_iterator it(folder, error), end; !error && it != end; it.increment(error)) {
    const std::string name = it->path().filename().string();
    if (!name.starts_with(prefix) || name.size() == prefix.size() ||
        name.size() > prefix.size() + 9 ||
        name.find_first_not_of("0123456789", prefix.size()) != std::string::npos) {
      continue;
    }
    const auto pid = static_cast<pid_t>(std::stol(name.substr(prefix.size())));
    std::error_code status_error;
    if (pid <= 0 || !fs::is_regular_file(fs::symlink_status(it->path(), status_error)) ||
        ::kill(pid, 0) == 0 || errno != ESRCH) {
      continue;  // a writer still running (or a pid this process cannot tell of)
    }
    const int fd = ::open(it->path().c_str(), O_RDONLY | O_NOFOLLOW | O_CLOEXEC | O_NONBLOCK);
    if (fd < 0) continue;
    std::string head(512, '\0');
    const ssize_t got = ::read(fd, head.data(), head.size());
    ::close(fd);
    head.resize(got > 0 ? static_cast<std::size_t>(got) : 0);
    if (ours(head)) fs::remove(it->path(), status_error);
  }
}

namespace {

// What `mode` is, for a refusal: "a FIFO", "a directory".
const char* FileKind(mode_t mode) {
  if (S_ISDIR(mode)) return "a directory";
  if (S_ISFIFO(mode)) return "a FIFO";
  if (S_ISCHR(mode)) return "a character device";
  if (S_ISBLK(mode)) return "a block device";
  if (S_ISSOCK(mode)) return "a socket";
  return "not a regular file";
}

// The reports and manifests name their inputs in JSON, which holds UTF-8 only.
void RefuseNonUtf8Name(const std::string& path) {
  if (!io::IsUtf8(path)) {
    throw InputError(io::Quoted(path, 200) +
                     ": the file's name is not UTF-8 (the reports name every input in UTF-8); "
                     "rename it");
  }
}

// Refuses what `info` describes unless a regular file of at most `max_bytes`.
void CheckRegular(const std::string& path, const struct stat& info, std::uint64_t max_bytes) {
  if (!S_ISREG(info.st_mode)) {
    throw InputError(path + ": is " + FileKind(info.st_mode) + " (expected a regular file)");
  }
  const auto size = static_cast<std::uint64_t>(info.st_size);
  if (size > max_bytes) {
    throw InputError(path + ": holds " + ByteCount(size) + ", more than the " +
                     ByteCount(max_bytes) + " sonarbench reads from such a file");
  }
}

}  // namespace

std::string ByteCount(std::uint64_t bytes) {
  if (bytes < 10240) return std::to_string(bytes) + " bytes";
  const char* units[] = {"KiB", "MiB", "GiB", "TiB"};
  double value = static_cast<double>(bytes) / 1024.0;
  int unit = 0;
  while (value >= 1024.0 && unit < 3) {
    value /= 1024.0;
    ++unit;
  }
  char text[32];
  std::snprintf(text, sizeof text, "%.3g %s", value, units[unit]);
  return text;
}

std::uint64_t CheckInputFile(const std::string& path, std::uint64_t max_bytes) {
  RefuseNonUtf8Name(path);
  struct stat info {};
  if (::stat(path.c_str(), &info) != 0) {
    throw InputError(path + ": cannot be read (" + std::strerror(errno) + ")");
  }
  CheckRegular(path, info, max_bytes);
  return static_cast<std::uint64_t>(info.st_size);
}

std::string ReadFileBytes(const std::string& path, std::uint64_t max_bytes) {
  RefuseNonUtf8Name(path);
  // O_NONBLOCK: a FIFO opens at once (and is refused by its type) instead of waiting for a writer.
  const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC | O_NOCTTY);
  if (fd < 0) throw InputError(path + ": cannot be read (" + std::strerror(errno) + ")");
  std::string bytes;
  try {
    struct stat info {};
    if (::fstat(fd, &info) != 0) {
      throw InputError(path + ": cannot be read (" + std::strerror(errno) + ")");
    }
    CheckRegular(path, info, max_bytes);
    bytes.resize(static_cast<std::size_t>(info.st_size));
    std::size_t done = 0;
    while (done < bytes.size()) {
      const ssize_t n = ::read(fd, bytes.data() + done, bytes.size() - done);
      if (n < 0 && errno == EINTR) continue;
      if (n < 0) throw InputError(path + ": cannot be read (" + std::strerror(errno) + ")");
      if (n == 0) break;  // shrank while read: what is there
      done += static_cast<std::size_t>(n);
    }
    bytes.resize(done);
  } catch (...) {
    ::close(fd);
    throw;
  }
  ::close(fd);
  return bytes;
}

}  // namespace sonarbench
