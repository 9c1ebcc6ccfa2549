#pragma once
// The temporaries of this process's outputs (core/atomic_output.h), registered while they exist: an interrupted run
// removes them (RemoveTemporaryOutputsForExit), and each holds a lock that tells a later run it is still live. For
// atomic_output.cc; other code writes through the classes there.

#include <filesystem>
#include <map>
#include <mutex>

namespace vmap::internal {

// A temporary's lock: a shared flock(2) held on it for as long as it is this process's. The pid in its name tells
// another vmap only whether a process of that pid runs in *its* PID namespace; two containers sharing a volume, or
// two hosts sharing a file system, would each take the other's running work for a killed process's leftovers. The
// lock is seen wherever the file is (local file systems, and NFS, which turns it into a byte-range lock).
// The descriptor, or -1 when the lock cannot be taken.
int HoldLock(const std::filesystem::path& path);

// Whether some process holds the lock of the temporary at `path` (its owner is alive, wherever it runs).
bool LockIsHeld(const std::filesystem::path& path);

// The temporaries this process created and has not yet committed or removed, each with its lock (-1: none).
struct TemporaryRegistry {
  std::mutex mutex;
  std::map<std::filesystem::path, int> paths;

  // Both with the mutex held.
  void Add(const std::filesystem::path& path);
  void Remove(const std::filesystem::path& path);
};

// Never destroyed: an interrupted process cleans up from another thread while main() may be returning.
TemporaryRegistry& Temporaries();

// Creates a temporary and registers it in one step under the registry's lock, so that an interruption
// never finds one created and not yet registered (it would stay behind).
template <typename Create>
auto CreateRegistered(const std::filesystem::path& path, Create&& create) -> decltype(create()) {
  std::lock_guard<std::mutex> lock(Temporaries().mutex);
  auto created = create();
  if (created) Temporaries().Add(path);
  return created;
}

// Removes the temporary at `path` and forgets it.
void RemoveAndUnregister(const std::filesystem::path& path);

}  // namespace vmap::internal
