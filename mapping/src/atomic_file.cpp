#include "sonarbench/mapping/atomic_file.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
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
  try {
    {
      errno = 0;
      std::ofstream out(temp, std::ios::binary | std::ios::trunc);
      if (!out) throw EnvironmentError(path + ": cannot be written (" + Reason() + ")");
      write(out);
      out.flush();
      if (!out) throw EnvironmentError(path + ": cannot be written (" + Reason() + ")");
      out.close();
      if (!out) throw EnvironmentError(path + ": cannot be written (" + Reason() + ")");
    }
    const int fd = ::open(temp.c_str(), O_RDONLY);
    if (fd < 0 || ::fsync(fd) != 0) {
      const std::string reason = std::strerror(errno);
      if (fd >= 0) ::close(fd);
      throw EnvironmentError(path + ": cannot be written (fsync: " + reason + ")");
    }
    ::close(fd);
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

std::string ReadFileBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path + ": cannot be read");
  std::stringstream bytes;
  bytes << in.rdbuf();
  return bytes.str();
}

}  // namespace sonarbench
