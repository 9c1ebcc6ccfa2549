#include "vmap/core/temporary_registry.h"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <string>
#include <thread>

#include <spdlog/spdlog.h>

#include "vmap/core/atomic_output.h"
#include "vmap/core/temporary_name.h"

namespace vmap {
namespace fs = std::filesystem;

namespace internal {

int HoldLock(const fs::path& path) {
  const int fd = open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NOFOLLOW | O_NONBLOCK);
  if (fd >= 0 && flock(fd, LOCK_SH | LOCK_NB) != 0) {
    close(fd);
    return -1;
  }
  return fd;
}

bool LockIsHeld(const fs::path& path) {
  const int fd = open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NOFOLLOW | O_NONBLOCK);
  if (fd < 0) return false;
  const bool held = flock(fd, LOCK_EX | LOCK_NB) != 0 && errno == EWOULDBLOCK;
  close(fd);
  return held;
}

void TemporaryRegistry::Add(const fs::path& path) {
  if (paths.count(path) == 0) paths[path] = HoldLock(path);
}

void TemporaryRegistry::Remove(const fs::path& path) {
  const auto found = paths.find(path);
  if (found == paths.end()) return;
  if (found->second >= 0) close(found->second);
  paths.erase(found);
}

TemporaryRegistry& Temporaries() {
  static TemporaryRegistry* registry = new TemporaryRegistry;
  return *registry;
}

void RemoveAndUnregister(const fs::path& path) {
  std::error_code ignored;
  fs::remove_all(path, ignored);
  std::lock_guard<std::mutex> lock(Temporaries().mutex);
  Temporaries().Remove(path);
}

}  // namespace internal

using internal::LockIsHeld;
using internal::Temporaries;

namespace {

// Calls visit(temporary, owner_pid) for each temporary beside `path` (".NAME.TAG-PID-N", core/temporary_name.h)
// until it returns false.
template <typename Visit>
void ForEachTemporaryOf(const fs::path& path, Visit&& visit) {
  const fs::path parent = path.has_parent_path() ? path.parent_path() : fs::path(".");
  const std::string name = path.filename().string();
  std::error_code ec;
  for (fs::directory_iterator it(parent, ec), end; !ec && it != end; it.increment(ec)) {
    const long pid = TemporaryOwner(it->path().filename().string(), name);
    if (pid != 0 && !visit(it->path(), pid)) return;
  }
}

// Whether the process that made `temporary` still runs: its pid in this PID namespace, or its lock wherever it runs.
bool OwnerIsAlive(const fs::path& temporary, long pid) { return ProcessRuns(pid) || LockIsHeld(temporary); }

}  // namespace

void RemoveStaleTemporaries(const fs::path& path) {
  ForEachTemporaryOf(path, [](const fs::path& temporary, long pid) {
    if (OwnerIsAlive(temporary, pid)) return true;
    std::error_code removed;
    fs::remove_all(temporary, removed);
    if (!removed) {
      spdlog::info("removed '{}', left behind by vmap process {}, which was killed", temporary.string(), pid);
    }
    return true;
  });
}

long OtherWriterOf(const fs::path& path) {
  const std::string partial = "." + path.filename().string() + ".partial-";
  long writer = 0;
  ForEachTemporaryOf(path, [&](const fs::path& temporary, long pid) {
    const bool other_live_partial = temporary.filename().string().rfind(partial, 0) == 0 &&
                                    pid != static_cast<long>(getpid()) && OwnerIsAlive(temporary, pid);
    if (other_live_partial) writer = pid;
    return !other_live_partial;
  });
  return writer;
}

int RemoveTemporaryOutputsForExit() {
  // Locked for good: nothing new is created or committed while the process ends.
  Temporaries().mutex.lock();
  int removed = 0;
  for (const auto& registered : Temporaries().paths) {
    const fs::path& path = registered.first;
    // Another thread may still be writing into a directory: a retry takes what appeared meanwhile. Once the
    // directory itself is gone, nothing recreates it (only the constructor does, under the lock held here).
    std::error_code ec;
    for (int attempt = 0; attempt < 1000 && fs::exists(fs::symlink_status(path, ec)); ++attempt) {
      if (attempt > 0) std::this_thread::sleep_for(std::chrono::milliseconds(1));
      fs::remove_all(path, ec);
    }
    ++removed;
  }
  Temporaries().paths.clear();
  return removed;
}

}  // namespace vmap
