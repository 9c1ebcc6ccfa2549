#pragma once
// A fresh temporary folder for one test, removed with everything in it at the end of its scope.

#include <filesystem>
#include <string>

namespace vmap::testing {

class ScopedTempDir {
 public:
  // A new, empty folder vmap_<name>_XXXXXX under the system's temporary folder (unique, so tests running in
  // parallel never share one); `name` tells whose folder it was if one is ever left behind.
  explicit ScopedTempDir(const std::string& name = "test");
  ~ScopedTempDir();
  ScopedTempDir(const ScopedTempDir&) = delete;
  ScopedTempDir& operator=(const ScopedTempDir&) = delete;

  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

// The bytes of a file a test wrote or wants to compare (empty when it cannot be read).
std::string ReadText(const std::filesystem::path& file);

}  // namespace vmap::testing
