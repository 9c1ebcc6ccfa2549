#include "vmap/testing/shared_data.h"

#include <filesystem>

namespace vmap::testing {

std::string SharedDir() {
  const std::filesystem::path dir(VMAP_SHARED_DIR);
  std::error_code error;
  if (!std::filesystem::is_directory(dir / "data", error)) return {};
  return std::filesystem::canonical(dir, error).string();
}

bool SharedDataPresent() { return !SharedDir().empty(); }

std::string NoSharedDataMessage() {
  return std::string("no shared data at ") + VMAP_SHARED_DIR + " (configure with -DVMAP_SHARED_DIR=...)";
}

}  // namespace vmap::testing
