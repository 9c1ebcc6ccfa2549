#pragma once
// Outputs are written so that an interrupted run never leaves a half-written file or map behind:
// everything goes to a temporary sibling first and is renamed into place at the end.

#include <filesystem>
#include <string>
#include <string_view>

namespace vmap {

// Writes `content` to `path` through a temporary file in the same directory and a rename.
void WriteFileAtomically(const std::filesystem::path& path, std::string_view content);

// A directory that only appears under its final name once Commit() is called. Until then the
// work happens in a hidden temporary sibling, removed if the object is destroyed uncommitted.
class AtomicOutputDirectory {
 public:
  // An existing directory at `final_path` is replaced on Commit() only when it is empty or holds the file
  // `ownership_marker` (e.g. "map.json": an older map), so that a mistyped -o never deletes a user's
  // folder. kReplaceAnything is for directories vmap owns outright (a map's report assets).
  AtomicOutputDirectory(std::filesystem::path final_path, const std::string& ownership_marker);
  static constexpr const char* kReplaceAnything = "";
  ~AtomicOutputDirectory();
  AtomicOutputDirectory(const AtomicOutputDirectory&) = delete;
  AtomicOutputDirectory& operator=(const AtomicOutputDirectory&) = delete;

  // The directory to write into now.
  const std::filesystem::path& path() const { return temp_path_; }
  const std::filesystem::path& final_path() const { return final_path_; }

  // Moves the finished directory into place (replacing an older one).
  void Commit();

 private:
  std::filesystem::path final_path_;
  std::filesystem::path temp_path_;
  bool committed_ = false;
};

}  // namespace vmap
