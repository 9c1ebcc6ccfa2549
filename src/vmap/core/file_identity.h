#pragma once
// What tells a file or a folder from another that later stands at the same path. vmap replaces an output whole,
// by a rename, so a new map is a new folder: another inode. The size and the modification time are part of it
// because a removal frees an inode that a copy made at once may take again.

#include <filesystem>
#include <optional>

namespace vmap {

struct FileIdentity {
  unsigned long device = 0;
  unsigned long inode = 0;
  long long size = 0;
  long long modified_ns = 0;

  bool operator==(const FileIdentity& other) const {
    return device == other.device && inode == other.inode && size == other.size && modified_ns == other.modified_ns;
  }
  bool operator!=(const FileIdentity& other) const { return !(*this == other); }
};

// The identity of what stands at `path` (a link is followed); nullopt when nothing does or it cannot be stat'ed.
std::optional<FileIdentity> IdentityOf(const std::filesystem::path& path);

// Whether `a` and `b` are the same file or folder (device and inode; both there): a folder stays itself while files
// are added to it, which changes its time and size.
bool SameFile(const std::optional<FileIdentity>& a, const std::optional<FileIdentity>& b);

}  // namespace vmap
