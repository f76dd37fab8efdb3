#include "sonarbench/base/atomic_file.hpp"

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

#include "sonarbench/base/error.hpp"

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

}  // namespace sonarbench
