#pragma once
// Durability across a power loss: a rename is put on disk before the data it names unless the data is synced first
// (ext4 orders it for a replaced file only, not for a folder), and the rename itself only once its directory is.
// Best effort: a file system that cannot sync (some FUSE and network ones) is written to as before.

#include <filesystem>

namespace vmap {

// fsync of a directory (empty: the working directory): the renames in it are on disk.
void SyncDirectory(const std::filesystem::path& directory);
// syncfs of the file system `directory` is on: every file written into a temporary folder, in one call, cheaper than
// one fsync a file (a map's key images).
void SyncFileSystemOf(const std::filesystem::path& directory);

}  // namespace vmap
