#pragma once
// Reading files that vmap did not necessarily write (a map someone sent, a folder from the internet) without
// being led outside the folder they belong to, into a device, or into reading more than was asked for.

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>

#include <nlohmann/json.hpp>

namespace vmap {

// Whether `inner` is `outer` or lies inside it, comparing the directories they resolve to (symbolic links,
// "..", bind mounts). A path that does not exist yet is compared through its existing ancestors.
bool IsSameOrInside(const std::filesystem::path& inner, const std::filesystem::path& outer);

// Whether `path` is relative and free of "..": it names something inside whatever folder it is relative to,
// as long as no symbolic link leads out (ContainedFile checks that too).
bool IsPlainRelativePath(const std::string& path);

// A regular file inside a folder, open for reading byte ranges (pread): the file is never read whole unless
// asked, so a sparse or huge file costs only what is read.
class ContainedFile {
 public:
  // Opens `directory`/`relative` when it is a regular file that resolves inside `directory`. Otherwise returns
  // nullopt and sets `*why_not` to "is missing", "resolves outside ..." (a symbolic link leading out), or "is
  // not a regular file" (a device, a FIFO, a folder), for the caller to name in its message. `relative` must
  // be a plain relative path (IsPlainRelativePath).
  static std::optional<ContainedFile> Open(const std::filesystem::path& directory, const std::string& relative,
                                           std::string* why_not);
  ContainedFile(ContainedFile&& other) noexcept;
  ContainedFile& operator=(ContainedFile&&) = delete;
  ContainedFile(const ContainedFile&) = delete;
  ~ContainedFile();

  const std::filesystem::path& path() const { return path_; }
  std::uint64_t size() const { return size_; }

  // Reads `bytes` bytes at `offset` into `data`; false when the file is shorter (it changed since Open) or
  // cannot be read.
  bool Read(std::uint64_t offset, void* data, std::size_t bytes) const;

 private:
  ContainedFile(std::filesystem::path path, int fd, std::uint64_t size) : path_(std::move(path)), fd_(fd), size_(size) {}

  std::filesystem::path path_;
  int fd_ = -1;
  std::uint64_t size_ = 0;
};

// A JSON file inside `directory` (a ContainedFile) of at most `max_bytes`, nested at most 64 deep, parsed.
// On failure `document` is empty and `why_not` says why, naming the file: "map.json is missing", "map.json is
// not valid JSON (...)".
struct ContainedJson {
  std::optional<nlohmann::json> document;
  std::string why_not;
  bool missing = false;  // the file does not exist
};
ContainedJson ReadContainedJson(const std::filesystem::path& directory, const std::string& name,
                                std::uint64_t max_bytes);

}  // namespace vmap
