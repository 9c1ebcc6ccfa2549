#include "vmap/core/directory_lock.h"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include <spdlog/spdlog.h>

#include "vmap/core/error.h"

namespace vmap {
namespace fs = std::filesystem;

namespace {

int OpenDirectory(const fs::path& path) { return open(path.c_str(), O_RDONLY | O_DIRECTORY | O_NOFOLLOW | O_CLOEXEC); }

bool SameFile(int fd, const fs::path& path) {
  struct stat open_stat, path_stat;
  return fstat(fd, &open_stat) == 0 && lstat(path.c_str(), &path_stat) == 0 && open_stat.st_dev == path_stat.st_dev &&
         open_stat.st_ino == path_stat.st_ino;
}

}  // namespace

DirectoryWriteLock::DirectoryWriteLock(const fs::path& directory, const std::string& what) {
  bool said_waiting = false;
  for (;;) {
    std::error_code ec;
    path_ = fs::canonical(directory, ec);
    if (ec || !fs::is_directory(path_, ec)) {
      throw InputError(what + " '" + directory.string() + "' is not a folder that can be opened (" +
                       (ec ? ec.message() : std::string("not a directory")) + ")");
    }
    fd_ = OpenDirectory(path_);
    if (fd_ < 0) {
      throw InputError("cannot open " + what + " '" + directory.string() + "' (" + std::strerror(errno) +
                       "); check its permissions");
    }
    int locked;
    while ((locked = flock(fd_, LOCK_EX | LOCK_NB)) != 0 && errno == EINTR) {
    }
    if (locked != 0 && errno == EWOULDBLOCK) {
      if (!said_waiting) {
        spdlog::info("{} '{}' is being written by another vmap process; waiting for it to finish", what,
                     directory.string());
        said_waiting = true;
      }
      while ((locked = flock(fd_, LOCK_EX)) != 0 && errno == EINTR) {
      }
    }
    if (locked != 0) {
      const std::string reason = std::strerror(errno);
      close(fd_);
      throw InputError("cannot lock " + what + " '" + directory.string() + "' for writing (" + reason +
                       "); vmap writes maps on local file systems");
    }
    // The holder may have replaced the folder (`build -o` exchanges it with a new one): the lock must be on
    // the folder the path names now.
    if (SameFile(fd_, path_)) return;
    close(fd_);
    fd_ = -1;
  }
}

DirectoryWriteLock::~DirectoryWriteLock() {
  if (fd_ >= 0) close(fd_);  // releases the lock
}

bool DirectoryWriteLock::IsHeldElsewhere(const fs::path& directory) {
  std::error_code ec;
  const fs::path real = fs::canonical(directory, ec);
  if (ec) return false;
  const int fd = OpenDirectory(real);
  if (fd < 0) return false;
  // flock locks belong to the open file description: this new one conflicts with every other holder, this
  // process's included.
  const bool held = flock(fd, LOCK_EX | LOCK_NB) != 0 && errno == EWOULDBLOCK;
  close(fd);
  return held;
}

}  // namespace vmap
