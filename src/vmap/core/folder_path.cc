#include "vmap/core/folder_path.h"

namespace vmap {
namespace fs = std::filesystem;

fs::path NormalizedFolderPath(const fs::path& path) {
  std::error_code ec;
  fs::path normal = fs::absolute(path, ec);
  normal = (ec ? path : normal).lexically_normal();
  // "run/images/" keeps an empty last name, whose parent_path() is the folder itself.
  if (!normal.has_filename() && normal.has_relative_path()) normal = normal.parent_path();
  return normal;
}

}  // namespace vmap
