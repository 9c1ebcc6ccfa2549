#include "vmap/core/file_identity.h"

#include <sys/stat.h>

namespace vmap {

std::optional<FileIdentity> IdentityOf(const std::filesystem::path& path) {
  struct stat status {};
  if (::stat(path.c_str(), &status) != 0) return std::nullopt;
  FileIdentity identity;
  identity.device = static_cast<unsigned long>(status.st_dev);
  identity.inode = static_cast<unsigned long>(status.st_ino);
  identity.size = static_cast<long long>(status.st_size);
  identity.modified_ns = static_cast<long long>(status.st_mtim.tv_sec) * 1000000000LL + status.st_mtim.tv_nsec;
  return identity;
}

bool SameFile(const std::optional<FileIdentity>& a, const std::optional<FileIdentity>& b) {
  return a && b && a->device == b->device && a->inode == b->inode;
}

}  // namespace vmap
