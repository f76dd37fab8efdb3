#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include "sonarbench/base/error.hpp"
#include "sonarbench/io/output_directory.hpp"
#include "sonarbench/io/text.hpp"

// The run's lock file: opened safely, the writers' names in it (a line each), read back.
namespace sonarbench::io {

// Opens the lock file, never through a symlink and never one with another name (a hard link):
// writing the holder's name would change a file elsewhere.
void OutputDirectory::OpenLockFile() {
  const std::string lock = name_ + "/" + kLockFile;
  lock_fd_ = ::open((root_ / kLockFile).c_str(),
                    O_RDWR | O_CREAT | O_CLOEXEC | O_NOFOLLOW | O_NONBLOCK | O_NOCTTY, 0644);
  if (lock_fd_ < 0 && errno == ELOOP) {
    throw InputError(lock + " is a symlink: sonarbench writes nothing through one (remove it)");
  }
  if (lock_fd_ < 0) {
    throw EnvironmentError(name_ + ": cannot write in it (" + std::strerror(errno) + ")");
  }
  struct stat info {};
  std::string refused;
  if (::fstat(lock_fd_, &info) != 0 || !S_ISREG(info.st_mode)) {
    refused = lock + " is not a regular file: sonarbench did not make it (remove it)";
  } else if (info.st_nlink != 1) {
    refused = lock + " has another name (a hard link): writing it would change a file " +
              "elsewhere; sonarbench did not make it (remove it)";
  }
  if (!refused.empty()) {
    ::close(lock_fd_);  // never truncated on the way out
    lock_fd_ = -1;
    throw InputError(refused);
  }
}

void OutputDirectory::WriteHolder(bool first) const {
  char host[256] = "?";
  ::gethostname(host, sizeof host - 1);
  const std::string text = "sonarbench " + claim_.command + ", pid " + std::to_string(::getpid()) +
                           " on " + host + ", config " + claim_.config_sha256.substr(0, 12) + "\n";
  // The first writer replaces the names of those before it (their temporaries are gone); each
  // shard that joins adds its own line, under the directory's lock.
  struct stat info {};
  const off_t at = first || ::fstat(lock_fd_, &info) != 0 ? 0 : info.st_size;
  if ((first && ::ftruncate(lock_fd_, 0) != 0) ||
      ::pwrite(lock_fd_, text.data(), text.size(), at) != static_cast<ssize_t>(text.size())) {
    throw EnvironmentError(name_ + "/" + kLockFile + ": cannot be written (" +
                           std::strerror(errno) + ")");
  }
}

std::string OutputDirectory::LockText() const {
  std::string text;
  char chunk[4096];
  for (ssize_t n;
       (n = ::pread(lock_fd_, chunk, sizeof chunk, static_cast<off_t>(text.size()))) > 0;) {
    text.append(chunk, static_cast<std::size_t>(n));
  }
  return text;
}

std::set<std::string> OutputDirectory::LockedWriters() const {
  const std::string text = LockText();
  std::set<std::string> pids;
  for (std::size_t at = text.find(", pid "); at != std::string::npos;
       at = text.find(", pid ", at + 6)) {
    const std::size_t end = text.find_first_not_of("0123456789", at + 6);
    if (end != at + 6 && end != std::string::npos) pids.insert(text.substr(at + 6, end - at - 6));
  }
  return pids;
}

std::string OutputDirectory::Holder() const {
  std::string holder = LockText().substr(0, 511);
  holder = holder.substr(0, holder.find('\n'));
  return holder.empty() ? "holder unknown" : io::Quoted(holder, 200);
}

}  // namespace sonarbench::io
