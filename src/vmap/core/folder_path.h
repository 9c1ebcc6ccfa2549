#pragma once
// A folder as users name it: "run/images", "run/images/" (as tab completion writes it) and "." all name one folder,
// whose parent is where a dataset keeps what lies beside it (timestamps.txt, intrinsics.txt, KITTI's poses/).

#include <filesystem>

namespace vmap {

// `path` made absolute, "." and ".." resolved by name, without a trailing separator: its parent_path() is the folder
// holding it ("run" for "run/images/"; the working folder's parent for ".").
std::filesystem::path NormalizedFolderPath(const std::filesystem::path& path);

}  // namespace vmap
