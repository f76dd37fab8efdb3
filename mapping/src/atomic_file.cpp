#include "sonarbench/mapping/atomic_file.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <ext/stdio_filebuf.h>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "sonarbench/mapping/error.hpp"

namespace sonarbench {
namespace {

// The OS's reason for the last failed call, or a plain word when the stream library left none.
std::string Reason() { return errno != 0 ? std::strerror(errno) : "write failed"; }

}  // namespace

void WriteFileAtomically(const std::string& path, const std::function<void(std::ostream&)>& write) {
  const std::string temp = path + ".tmp." + std::to_string(::getpid());
  // A new file, never one there already nor through a symlink: nothing else is truncated.
  const int fd =
      ::open(temp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC | O_NOCTTY, 0666);
  if (fd < 0) throw EnvironmentError(path + ": cannot be written (" + temp + ": " + Reason() + ")");
  try {
    {
      __gnu_cxx::stdio_filebuf<char> buffer(fd, std::ios::out | std::ios::binary, 1 << 16);
      std::ostream out(&buffer);
      errno = 0;
      write(out);
      out.flush();
      if (!out) throw EnvironmentError(path + ": cannot be written (" + Reason() + ")");
      if (::fsync(fd) != 0) {
        throw EnvironmentError(path + ": cannot be written (fsync: " + Reason() + ")");
      }
      errno = 0;
      if (buffer.close() == nullptr) {
        throw EnvironmentError(path + ": cannot be written (" + Reason() + ")");
      }
    }
    std::error_code error;
    std::filesystem::rename(temp, path, error);
    if (error) throw EnvironmentError(path + ": cannot be written (" + error.message() + ")");
  } catch (...) {
    std::error_code ignored;
    std::filesystem::remove(temp, ignored);
    throw;
  }
}

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
  struct stat info {};
  if (::stat(path.c_str(), &info) != 0) {
    throw InputError(path + ": cannot be read (" + std::strerror(errno) + ")");
  }
  CheckRegular(path, info, max_bytes);
  return static_cast<std::uint64_t>(info.st_size);
}

std::string ReadFileBytes(const std::string& path, std::uint64_t max_bytes) {
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
