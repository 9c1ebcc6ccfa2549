#include "vmap/core/file_sync.h"

#include <fcntl.h>
#include <unistd.h>

namespace vmap {
namespace fs = std::filesystem;

void SyncDirectory(const fs::path& directory) {
  const int fd = open(directory.empty() ? "." : directory.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd < 0) return;
  fsync(fd);
  close(fd);
}
void SyncFileSystemOf(const fs::path& directory) {
  const int fd = open(directory.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd < 0) return;
  syncfs(fd);
  close(fd);
}

}  // namespace vmap
