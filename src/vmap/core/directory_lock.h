#pragma once
// Writers of one folder exclude each other: `vmap build --add-experience-to MAP` rewrites MAP/map.json and adds
// MAP/experiences/<id>/, `vmap build -o MAP` replaces MAP, and two of them at once would each undo the other's
// work (each reads map.json, then writes it back with only its own experience); `vmap report MAP` writes a page
// describing the map it read. Each writer holds an
// exclusive flock(2) on the folder itself while it reads what it will change and writes it. The kernel drops
// the lock when the process ends however it ends (a crash, SIGKILL), so no stale lock ever needs removing,
// and nothing is added to the folder. Readers take no lock: writers only ever rename complete files into place.

#include <filesystem>
#include <string>

namespace vmap {

class DirectoryWriteLock {
 public:
  // Locks the folder `directory` (a symbolic link the user named is resolved first; the lock is on the folder
  // it leads to). While another process holds the lock, waits for it and says so once at info level, naming
  // `what` ("the map"); a folder replaced meanwhile (renamed away by the holder) is locked again under its
  // path. Throws InputError when the folder does not exist or cannot be opened.
  DirectoryWriteLock(const std::filesystem::path& directory, const std::string& what);
  ~DirectoryWriteLock();
  DirectoryWriteLock(const DirectoryWriteLock&) = delete;
  DirectoryWriteLock& operator=(const DirectoryWriteLock&) = delete;

  // The folder as locked: its real path (no symbolic link left in it), and an open descriptor of it.
  const std::filesystem::path& path() const { return path_; }
  int fd() const { return fd_; }

  // Whether another process holds the lock on `directory` now (for tests and messages). False when the folder
  // does not exist.
  static bool IsHeldElsewhere(const std::filesystem::path& directory);

 private:
  std::filesystem::path path_;
  int fd_ = -1;
};

}  // namespace vmap
